#include "mesh/staged_write.hpp"

#include <pthread.h>

#include <chrono>
#include <ctime>
#include <filesystem>

#include "mesh/atomic_file.hpp"
#include "mesh/error.hpp"

namespace hexrefine {

namespace {

double thread_cpu_seconds(clockid_t clock) {
  timespec ts{};
  if (::clock_gettime(clock, &ts) != 0) return 0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// `message` with every occurrence of `from` replaced by `to`.
std::string message_with_path_replaced(std::string message, const std::string& from,
                                       const std::string& to) {
  for (size_t at = message.find(from); at != std::string::npos; at = message.find(from, at))
    message.replace(at, from.size(), to), at += to.size();
  return message;
}

}  // namespace

StagedMeshWrite::StagedMeshWrite(const std::string& path, const HexMesh& mesh,
                                 const MeshWriteOptions& options)
    : path_(path), staging_(file_staging_beside(path)) {
  thread_ = std::thread([this, &mesh, &options] {
    const auto start = std::chrono::steady_clock::now();
    try {
      mesh_write(staging_, mesh, options);
    } catch (...) {
      error_ = std::current_exception();
    }
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cpu_seconds_ = thread_cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    done_.store(true, std::memory_order_release);
  });
}

StagedMeshWrite::~StagedMeshWrite() {
  if (thread_.joinable()) thread_.join();
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(staging_, ignored);
  }
}

double StagedMeshWrite::cpu_seconds_so_far() const {
  if (done_.load(std::memory_order_acquire) || !thread_.joinable()) return cpu_seconds_;
  clockid_t clock;
  if (pthread_getcpuclockid(const_cast<std::thread&>(thread_).native_handle(), &clock) != 0)
    return 0;
  return thread_cpu_seconds(clock);
}

void StagedMeshWrite::finish() {
  if (thread_.joinable()) thread_.join();
  if (!error_) return;
  // The messages name the file the user asked for, and keep their kind (exit code).
  try {
    std::rethrow_exception(error_);
  } catch (const InputError& e) {
    throw InputError(message_with_path_replaced(e.what(), staging_, path_));
  } catch (const OperationError& e) {
    throw OperationError(message_with_path_replaced(e.what(), staging_, path_));
  }
}

void StagedMeshWrite::commit() {
  finish();
  file_commit_temporary(staging_, path_);
  committed_ = true;
}

}  // namespace hexrefine
