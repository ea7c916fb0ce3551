#pragma once
// The Gmsh C++ API for the demo models (and tests that build comparison meshes with it): the
// only place that calls libgmsh, so that io and every command but `geode demo` run without
// loading it (docs/developer-guide.md, "Startup").
#include <string_view>

#include <geode/primal/model.hpp>

namespace geode::demo {

// RAII: a clean Gmsh API state for one build: Gmsh initialized (no config files) the first time,
// then per session an empty model, the options any session here sets back at Gmsh's defaults,
// and General.Terminal = 0; the model cleared on destruction. Gmsh is never finalized: libgmsh
// 4.8 aborts meshing pyramids after gmsh::finalize and gmsh::initialize (an Eigen assertion in
// RelocateVerticesOfPyramids: a second hybrid demo in one process, tests/demo). Gmsh's state
// is global: do not nest sessions or use them from several threads.
class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// Converts Gmsh's current model (inside a GmshSession) to a Model, as io::read_gmsh does after
// opening (io/gmsh.hpp's mapping); `source` names it in error messages.
primal::Model model_from_gmsh(std::string_view source);

}  // namespace geode::demo
