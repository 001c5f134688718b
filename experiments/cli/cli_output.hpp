#pragma once
/// \file
/// Checks of an output path made before a command does any work, so that a long refinement or
/// smoothing is not thrown away at the end because its output cannot be written.

#include <string>

#include "experiments/cli/cli.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

/// What a command will write at `path`.
enum class CliOutputKind { mesh, report };

/// Refuses, with an InputError naming `command` and `path` (exit 2), an output path that cannot
/// be written: a mesh path with an unknown extension (mesh_format_of's message), a path that is
/// an existing folder, a missing parent folder, or a folder in which no file can be created (the
/// check creates and removes an empty probe file there, as file_write_atomically would create its
/// temporary file, so it also catches read-only file systems and, for non-root users,
/// permissions). A later failure (disk full, the folder removed meanwhile) is still an
/// OperationError from the writer.
void cli_output_check(const std::string& command, const std::string& path, CliOutputKind kind);

/// The mesh writer's encoding switches of a command writing `path`: --binary (VTK legacy
/// BINARY), --ascii and --compress (VTU text, VTU zlib). InputError naming `command` when a
/// switch does not apply to the format of `path`.
MeshWriteOptions cli_mesh_write_options(const CliArgs& a, const std::string& command,
                                        const std::string& path);

}  // namespace hexrefine
