#include "experiments/cli/cli_output.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "mesh/error.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

void cli_output_check(const std::string& command, const std::string& path, CliOutputKind kind) {
  namespace fs = std::filesystem;
  if (path.empty()) throw InputError(command + ": empty output path");
  if (kind == CliOutputKind::mesh) mesh_format_of(path);
  const std::string refused = command + ": cannot write " + path + ": ";
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(refused + "it is a folder");
  const fs::path parent = fs::path(path).parent_path();
  const fs::path folder = parent.empty() ? fs::path(".") : parent;
  if (!fs::is_directory(folder, ec))
    throw InputError(refused + "folder " + folder.string() + " does not exist");
  // mkstemp creates the probe with O_EXCL, so it never touches an existing file.
  std::string probe = (folder / ".hexrefine_probe_XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0)
    throw InputError(refused + "cannot create a file in folder " + folder.string() + " (" +
                     std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

MeshWriteOptions cli_mesh_write_options(const CliArgs& a, const std::string& command,
                                        const std::string& path) {
  MeshWriteOptions options;
  const MeshFormat format = mesh_format_of(path);
  options.binary = a.flag("--binary");
  options.ascii = a.flag("--ascii");
  options.compress = a.flag("--compress");
  if (options.binary && format != MeshFormat::vtk_legacy && format != MeshFormat::gmsh)
    throw InputError(command + ": --binary applies to .vtk and .msh output only (" + path + ")");
  if ((options.ascii || options.compress) && format != MeshFormat::vtu)
    throw InputError(command + ": --ascii and --compress apply to .vtu output only (" + path + ")");
  if (options.ascii && options.compress)
    throw InputError(command + ": --ascii and --compress exclude each other");
  return options;
}

}  // namespace hexrefine
