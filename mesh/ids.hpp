#pragma once
/// \file
/// Typed ids for the places where ids of different entities meet (node keys, refinement plans,
/// node constraints): a HexId cannot be passed where an EdgeId is expected. Storage stays
/// plain int32_t arrays (mesh/topology.hpp); these wrap an id only at such interfaces.

#include <cstdint>

namespace hexrefine {

enum class NodeId : int32_t {};
enum class EdgeId : int32_t {};
enum class FaceId : int32_t {};
enum class HexId : int32_t {};

/// The plain index of a typed id.
constexpr int32_t index_of(NodeId id) {
  return static_cast<int32_t>(id);
}
constexpr int32_t index_of(EdgeId id) {
  return static_cast<int32_t>(id);
}
constexpr int32_t index_of(FaceId id) {
  return static_cast<int32_t>(id);
}
constexpr int32_t index_of(HexId id) {
  return static_cast<int32_t>(id);
}

}  // namespace hexrefine
