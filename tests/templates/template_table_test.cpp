// The template table (templates/template_table.hpp): every entry complete, names unique,
// conform's cells each filled by one entry, and the entries derive what their names promise.
#include <doctest/doctest.h>

#include <set>
#include <string>

#include <geode/primal/errors.hpp>
#include <geode/templates/template_table.hpp>

using namespace geode;
using namespace geode::templates;

TEST_CASE("template table: every entry is complete and its name unique") {
  std::set<std::string_view> names;
  for (const TemplateEntry& e : template_table()) {
    CAPTURE(e.name);
    CHECK(names.insert(e.name).second);
    CHECK(!e.summary.empty());
    CHECK((e.dim == 2 || e.dim == 3));
    CHECK((e.spec != nullptr));
    CHECK((e.build != nullptr));
    CHECK(find_template(e.name) == &e);
    // Studies sweep the geode family's push; the paper's conditions are 3D geode conditions.
    if (e.study_grid) CHECK(e.family == TemplateFamily::kGeode);
    if (e.interleave_conditions) CHECK((e.family == TemplateFamily::kGeode && e.dim == 3));
    if (e.conform_use != ConformUse::kNone)
      CHECK((e.family == TemplateFamily::kGeode && e.dim == 3));
  }
  CHECK(find_template("geode5d") == nullptr);
  CHECK(template_names(true) == std::vector<std::string>{"geode3d", "geode4tri"});
  CHECK(template_help().find("geode2d: the 5-quad 2D geode") != std::string::npos);
  CHECK(conform_template(ConformUse::kTwoTriangles).defaults.geode.split ==
        TopSplit::kTwoTriangles);
  CHECK(conform_template(ConformUse::kFourTriangles).defaults.geode.split ==
        TopSplit::kFourTriangles);
  CHECK_THROWS_AS(conform_template(ConformUse::kNone), TopologyError);
}

TEST_CASE("template table: the cheap entries derive their templates through the table") {
  struct Case {
    const char* name;
    std::size_t cells;
  };
  for (const Case c :
       {Case{"geode3d", 26}, Case{"geode2d", 5}, Case{"refine3-2d", 4}, Case{"refine3", 13}}) {
    CAPTURE(c.name);
    const TemplateEntry& e = *find_template(c.name);
    const TemplateOptions o = template_options(e, e.defaults.geode, e.defaults.refine);
    const Template t = e.build(o);
    CHECK(t.dim == e.dim);
    CHECK((e.dim == 3 ? t.hex.hexes.size() : t.quad.quads.size()) == c.cells);
    // The spec is the template's arrangement: it builds the same mesh.
    const Template s = build_template(e.spec(o));
    CHECK((e.dim == 3 ? s.hex.hexes.size() : s.quad.quads.size()) == c.cells);
  }
}

TEST_CASE("template table: the options keep the entry's split whatever the caller gives") {
  const TemplateEntry& e = *find_template("geode4tri");
  GeodeOptions given;  // two triangles
  given.box = Eigen::Vector3d(20, 10, 20);
  const TemplateOptions o = template_options(e, given, {});
  CHECK(o.geode.split == TopSplit::kFourTriangles);
  CHECK(o.geode.box == given.box);
}
