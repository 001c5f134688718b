#pragma once
/// \file
/// The body every reader fuzz target shares: read the bytes as a file named `name` (its
/// extension picks the format) through mesh_read_from_memory. Bad input must end in InputError;
/// any other exception, a crash, a sanitizer report, a hang or an allocation beyond libFuzzer's
/// limit is a finding. A mesh that is accepted must satisfy the reader's promises (ids in range,
/// distinct per hex, finite coordinates, attributes of the right length): otherwise trap.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mesh/error.hpp"
#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

inline int fuzz_read_mesh(const char* name, const uint8_t* data, size_t size) {
  HexMesh mesh;
  try {
    mesh = mesh_read_from_memory(name, std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const InputError&) {
    return 0;  // refused with a message: the expected outcome for most inputs
  }
  try {
    mesh_validate_ids(mesh, name);
  } catch (const InputError&) {
    __builtin_trap();  // the reader accepted a mesh with bad ids
  }
  for (const Eigen::Vector3d& p : mesh.points)
    if (!p.allFinite()) __builtin_trap();  // the reader accepted NaN or infinity
  return 0;
}

}  // namespace hexrefine

/// Defines the libFuzzer entry point of a target reading files named `name`.
#define HEXREFINE_FUZZ_TARGET(name)                                         \
  extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) { \
    return hexrefine::fuzz_read_mesh(name, data, size);                     \
  }
