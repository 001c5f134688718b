#pragma once
/// \file
/// A mesh written on a thread of its own while the caller goes on (the `refine` command checks
/// the mesh meanwhile): the file goes to a staging path beside the output, with the output's
/// extension so mesh_write picks the same format, and becomes the output only on commit(), once
/// the caller's verdict allows it. Destroyed without a commit (an invalid result, an exception)
/// it waits for the writer and removes the staging file, so the output is never replaced by a
/// file the verdict refused. The mesh and options must stay unchanged and alive until finish()
/// or destruction: the writer reads them while the caller may only read them too.

#include <atomic>
#include <exception>
#include <string>
#include <thread>

#include "mesh/hex_mesh.hpp"
#include "mesh/io.hpp"

namespace hexrefine {

class StagedMeshWrite {
 public:
  /// Starts writing `mesh` for `path` (mesh_write's format, checks and options).
  StagedMeshWrite(const std::string& path, const HexMesh& mesh, const MeshWriteOptions& options);
  /// The writer reads the mesh and options after the constructor returns: temporaries would be
  /// gone by then.
  StagedMeshWrite(const std::string&, HexMesh&&, const MeshWriteOptions&) = delete;
  StagedMeshWrite(const std::string&, const HexMesh&, MeshWriteOptions&&) = delete;
  ~StagedMeshWrite();
  StagedMeshWrite(const StagedMeshWrite&) = delete;
  StagedMeshWrite& operator=(const StagedMeshWrite&) = delete;

  /// CPU seconds the writer thread has used so far (its own clock; the total once it is done).
  double cpu_seconds_so_far() const;
  /// Waits for the writer; rethrows what mesh_write threw, naming `path` (not the staging file).
  void finish();
  /// After finish(): renames the staging file to `path` (OperationError naming `path` on failure).
  void commit();
  /// After finish(): the writer's wall time and its thread's CPU time.
  double seconds() const { return seconds_; }
  double cpu_seconds() const { return cpu_seconds_; }

 private:
  std::string path_, staging_;
  std::exception_ptr error_;
  double seconds_ = 0, cpu_seconds_ = 0;
  bool committed_ = false;
  std::atomic<bool> done_{false};  // set by the writer after seconds_ and cpu_seconds_
  std::thread thread_;             // last: started once the members above exist
};

}  // namespace hexrefine
