#pragma once
/// \file
/// Every file hexrefine writes goes through here: written to a temporary file in the same folder,
/// flushed, then renamed over the target, so an interrupted run never leaves a half-written file
/// in place of a good one.

#include <functional>
#include <ostream>
#include <string>

namespace hexrefine {

/// Calls `write` with a binary stream on a temporary file beside `path`, then renames it to
/// `path`. Throws OperationError naming the path if it cannot be created, written or renamed
/// (the temporary file is removed).
void file_write_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write);

/// A temporary path beside `path` for writers that need a file name (e.g. the Exodus II library);
/// pair with file_commit_temporary.
std::string file_temporary_beside(const std::string& path);

/// A staging path beside `path` that keeps its file name, hence its extension and format:
/// "dir/.staged<pid>.<n>.name.ext" (hidden, unique in this process). Pair with
/// file_commit_temporary.
std::string file_staging_beside(const std::string& path);

/// Renames `temporary` to `path` (throws OperationError and removes `temporary` on failure).
void file_commit_temporary(const std::string& temporary, const std::string& path);

}  // namespace hexrefine
