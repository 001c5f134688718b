#pragma once
/// \file
/// The two kinds of failure every command distinguishes (exit codes: 0 done, 1 the operation
/// failed, 2 bad usage or bad input).

#include <cstdint>
#include <stdexcept>
#include <string>

namespace hexrefine {

/// Bad usage or bad input (exit code 2). The message names the file and line, or the entity,
/// and what was expected.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The operation could not be carried out on valid input (exit code 1), e.g. a refiner that
/// meets a configuration it cannot handle. The message says why and names the entities.
class OperationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Node placement could not make every child of a valid input valid (after its retargets and
/// fallback): a limit of the placement method, not of the input. The pipeline may try another
/// placement (algorithms/pipeline/pipeline.cpp).
class PlacementError : public OperationError {
 public:
  using OperationError::OperationError;
};

/// "file:line: message" (line 0 is left out: the error concerns the whole file).
std::string error_at(const std::string& file, int64_t line, const std::string& message);

}  // namespace hexrefine
