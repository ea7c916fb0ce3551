#include <geode/io/gmsh.hpp>

#include <geode/io/file_format.hpp>
#include <geode/io/mapped_file.hpp>

namespace geode::io {

using namespace primal;

Model read_gmsh(const std::filesystem::path& path, const ReadOptions& options) {
  check_mesh_format(path, MeshFileFormat::kGmsh);
  return parse_gmsh(MappedFile(path).bytes(), path.string(), options);
}

Model read_gmsh_partitioned(const std::filesystem::path& path, const ReadOptions& options,
                            FilePartition* partition) {
  check_mesh_format(path, MeshFileFormat::kGmsh);
  return parse_gmsh(MappedFile(path).bytes(), path.string(), options, partition);
}

}  // namespace geode::io
