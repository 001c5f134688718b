#pragma once
/// \file
/// How a movable node may move: freely, on a bilinear patch of the input's boundary, along a
/// straight boundary edge, or on a union of them; the nearest point of its slide and the tangent
/// space there. Shared by the node-by-node optimizer (node_optimizer.hpp) and the joint ascent
/// (node_joint_ascent.hpp), so both keep a boundary node on the input's boundary surface by
/// construction: every position they give a sliding node is a projection onto its slide.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "mesh/quad_patch.hpp"

namespace hexrefine {

/// How a movable node may move.
enum class SlideKind : uint8_t {
  free,      ///< anywhere: a node inside the domain
  patch,     ///< on one bilinear patch (a quad of the input's boundary), (u, v) in [0,1]^2
  segment,   ///< on one straight segment (an edge of the input's boundary), t in [0,1]
  patches,   ///< on the union of several patches (the boundary quads around a node)
  segments,  ///< on the union of several segments (a feature curve's edges around a node)
};

/// 3 for a free node, 2 on patches, 1 on segments: the dimension of the slide.
int slide_dimension(SlideKind kind);

/// The slide of one node: its kind and its patches or segments (SlideGeometry::items[first ..
/// first + count)).
struct NodeSlide {
  SlideKind kind = SlideKind::free;
  int32_t first = 0, count = 0;
};

/// What nodes slide on: reference positions, fixed while the nodes move.
struct SlideGeometry {
  std::vector<Quad> patches;
  std::vector<std::array<Eigen::Vector3d, 2>> segments;
  std::vector<int32_t> items;  ///< patch or segment ids of the slides
};

/// Where a sliding node is on its slide: the patch or segment (id into SlideGeometry::patches or
/// ::segments; -1: not placed yet) and its parameters there ((u, v) on a patch, (t, 0) on a
/// segment).
struct SlideState {
  int32_t item = -1;
  double u = 0.5, v = 0.5;
};

/// The point of `slide` nearest to x (x itself for a free node), and in `state` where it is.
/// A patch's Gauss-Newton projection starts from `state`'s parameters when `state` is on that
/// patch (a node that moved a little is found in one or two steps), else from its centre; over
/// several items the nearest wins, the first on a tie.
Eigen::Vector3d slide_project(const NodeSlide& slide, const SlideGeometry& geometry,
                              const Eigen::Vector3d& x, SlideState& state);

/// g projected onto the tangent space of `slide` at `state`: the patch's tangent plane
/// (S_u, S_v; zero where they are parallel), the segment's direction, g itself for a free node
/// or a state not placed yet.
Eigen::Vector3d slide_tangent(const NodeSlide& slide, const SlideGeometry& geometry,
                              const SlideState& state, const Eigen::Vector3d& g);

}  // namespace hexrefine
