#include "mesh/io_text.hpp"
namespace hexrefine::io_detail {
HexMesh gmsh_read(const std::string& path) {
  throw InputError(path + ": not implemented");
}
void gmsh_write(const std::string& path, const HexMesh&,
                const std::vector<std::pair<std::string, std::vector<double>>>&) {
  throw OperationError(path + ": not implemented");
}
HexMesh exodus_read(const std::string& path) {
  throw InputError(path + ": not implemented");
}
void exodus_write(const std::string& path, const HexMesh&) {
  throw OperationError(path + ": not implemented");
}
HexMesh abaqus_read(const std::string& path) {
  throw InputError(path + ": not implemented");
}
void abaqus_write(const std::string& path, const HexMesh&) {
  throw OperationError(path + ": not implemented");
}
}  // namespace hexrefine::io_detail
