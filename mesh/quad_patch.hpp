#pragma once
/// \file
/// The bilinear patch of a quad (a hex face), S(u, v) = (1-u)(1-v) q0 + u(1-v) q1 + uv q2 +
/// (1-u)v q3 over [0,1]^2 with q cyclic (q2 opposite q0): the surface a hex's trilinear map
/// gives its face. Shared by the checker (is a point on a face?), node placement and smoothing
/// (nodes that slide on the input's boundary).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace hexrefine {

using Quad = std::array<Eigen::Vector3d, 4>;

/// S(u, v). Unit square corners (u, v) = (0,0), (1,0), (1,1), (0,1) give q0..q3.
Eigen::Vector3d quad_point(const Quad& q, double u, double v);

/// The partial derivatives S_u and S_v at (u, v).
std::array<Eigen::Vector3d, 2> quad_tangents(const Quad& q, double u, double v);

/// The longer diagonal.
double quad_diameter(const Quad& q);

/// Unit normal of the quad's diagonals, (q2 - q0) x (q3 - q1) normalized (the patch normal at
/// its centre); zero when |(q2 - q0) x (q3 - q1)| <= 1e-12 x the longer diagonal squared (a
/// degenerate quad). Unit square q0..q3 = (0,0,0), (1,0,0), (1,1,0), (0,1,0): +z.
Eigen::Vector3d quad_unit_normal(const Quad& q);

/// Area of the patch: the integral of |S_u x S_v| by 3x3 Gauss points (exact for planar quads,
/// where the integrand is linear; an approximation for warped ones). Unit square: 1.
double quad_area(const Quad& q);

/// Out-of-plane spread of the four corners along the normal of the diagonals (0 if degenerate).
double quad_warp(const Quad& q);

/// quad_warp over the diameter (0 for a planar quad).
double quad_relative_warp(const Quad& q);

/// The patch point nearest to p: Gauss-Newton on (u, v) clamped to [0,1]^2, from (u0, v0). Exact
/// for planar convex quads; for mildly warped quads it converges to the nearest patch point.
struct QuadProjection {
  double u = 0.5, v = 0.5;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0;
};
QuadProjection quad_closest_point(const Quad& q, const Eigen::Vector3d& p, double u0 = 0.5,
                                  double v0 = 0.5);

/// Distance from p to the patch: quad_closest_point's, bounded by the nearest corner (degenerate
/// patches, where no Newton step is possible, still get an answer).
double quad_distance(const Quad& q, const Eigen::Vector3d& p);

/// Whether some patch point lies within `tolerance` of p: yes wherever quad_distance(q, p) <=
/// tolerance, found sooner where it is yes: one Gauss-Newton step from the centre (exact for a
/// parallelogram, the usual face of a refined mesh) gives a patch point, and if that one is within
/// the tolerance nothing more is computed; otherwise quad_distance decides. That step can also
/// find a point quad_distance's clamped Newton missed (it may stop on the patch's border short of
/// the nearest point, off a skewed quad's side): then the yes is the truer answer.
bool quad_within(const Quad& q, const Eigen::Vector3d& p, double tolerance);

}  // namespace hexrefine
