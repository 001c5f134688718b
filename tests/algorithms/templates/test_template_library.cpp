#include "algorithms/templates/template_library.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "mesh/error.hpp"
#include "mesh/hex_convention.hpp"

namespace hexrefine {
namespace {

using Point2 = std::array<long, 2>;   // face coordinates in sixths
using Quad2 = std::array<Point2, 4>;  // sorted

Quad2 quad_sorted(Quad2 q) {
  std::sort(q.begin(), q.end());
  return q;
}

// The face template a face must carry given which of its sides are split (sides: 0 v=0, 1 u=1,
// 2 v=1, 3 u=0), as sorted quads in sixths.
std::set<Quad2> face_template_expected(const std::array<bool, 4>& split) {
  std::set<Quad2> out;
  const int n = split[0] + split[1] + split[2] + split[3];
  auto add = [&](std::vector<Quad2> quads, int side) {
    for (Quad2 q : quads) {
      for (Point2& p : q) {
        const long u = p[0], v = p[1];
        if (side == 1) p = {6 - v, u};
        if (side == 2) p = {u, 6 - v};
        if (side == 3) p = {v, u};
      }
      out.insert(quad_sorted(q));
    }
  };
  if (n == 0) {
    add({{{{0, 0}, {6, 0}, {6, 6}, {0, 6}}}}, 0);
  } else if (n == 1) {
    const int side = split[0] ? 0 : split[1] ? 1 : split[2] ? 2 : 3;
    add({{{{0, 0}, {2, 0}, {2, 3}, {0, 6}}},
         {{{2, 0}, {4, 0}, {4, 3}, {2, 3}}},
         {{{4, 0}, {6, 0}, {6, 6}, {4, 3}}},
         {{{2, 3}, {4, 3}, {6, 6}, {0, 6}}}},
        side);
  } else if (n == 2 && split[0] == split[2]) {
    add({{{{0, 0}, {2, 0}, {2, 6}, {0, 6}}},
         {{{2, 0}, {4, 0}, {4, 6}, {2, 6}}},
         {{{4, 0}, {6, 0}, {6, 6}, {4, 6}}}},
        split[0] ? 0 : 1);
  } else if (n == 4) {
    std::vector<Quad2> q;
    for (long i = 0; i < 3; ++i)
      for (long j = 0; j < 3; ++j)
        q.push_back(
            {{{2 * i, 2 * j}, {2 * i + 2, 2 * j}, {2 * i + 2, 2 * j + 2}, {2 * i, 2 * j + 2}}});
    add(q, 0);
  }
  return out;
}

// Checks every face of a canonical template against the face template its split sides call for.
// Faces listed in `collapsed` (adjusted faces) are skipped. Returns the number of faces checked.
int template_faces_check(const HexTemplate& t, std::set<int> collapsed = {}) {
  auto six = [](double x) { return std::lround(6 * x); };
  int checked = 0;
  for (int f = 0; f < 6; ++f) {
    if (collapsed.count(f)) continue;
    const int axis = f / 2, side = f % 2;
    const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
    std::array<bool, 4> split{};
    for (const TemplateNode& n : t.nodes) {
      if (n.adjustment_edge >= 0 || six(n.ref[axis]) != 6 * side) continue;
      const long u = six(n.ref[ua]), v = six(n.ref[va]);
      if (std::abs(6 * n.ref[ua] - u) > 1e-9 || std::abs(6 * n.ref[va] - v) > 1e-9) continue;
      if (u == 2 && v == 0) split[0] = true;
      if (u == 6 && v == 2) split[1] = true;
      if (u == 2 && v == 6) split[2] = true;
      if (u == 0 && v == 2) split[3] = true;
    }
    std::set<Quad2> actual;
    for (const auto& c : t.children) {
      for (int lf = 0; lf < 6; ++lf) {
        Quad2 q;
        bool on = true;
        for (int i = 0; i < 4; ++i) {
          const TemplateNode& n = t.nodes[c[hex_faces[lf][i]]];
          on = on && n.adjustment_edge < 0 && std::abs(n.ref[axis] - side) < 1e-12;
          q[i] = {six(n.ref[ua]), six(n.ref[va])};
        }
        if (on) actual.insert(quad_sorted(q));
      }
    }
    EXPECT_EQ(actual, face_template_expected(split)) << template_tag_name(t.tag) << " face " << f;
    ++checked;
  }
  return checked;
}

TEST(Templates, SplitEdgeMasks) {
  EXPECT_EQ(template_split_edges(template_1_27()), 0xFFF);
  EXPECT_EQ(template_split_edges(template_1_3()), (1 << 0) | (1 << 2) | (1 << 4) | (1 << 6));
  EXPECT_EQ(template_split_edges(template_1_4()), (1 << 0) | (1 << 4));
  EXPECT_EQ(template_split_edges(template_1_5()), 1 << 0);
}

TEST(Templates, EachTemplateAloneIsValidWithTheRightChildCount) {
  EXPECT_EQ(template_1_27().children.size(), 27u);
  EXPECT_EQ(template_1_5().children.size(), 5u);
  EXPECT_EQ(template_1_4().children.size(), 4u);
  EXPECT_EQ(template_1_3().children.size(), 3u);
  EXPECT_DOUBLE_EQ(template_validate(template_1_27()), 1.0);
  EXPECT_DOUBLE_EQ(template_validate(template_1_3()), 1.0);
  EXPECT_GT(template_validate(template_1_4()), 0.5);
  EXPECT_GT(template_validate(template_1_5()), 0.4);
}

TEST(Templates, FacesMatchTheFaceTemplates) {
  EXPECT_EQ(template_faces_check(template_1_27()), 6);
  EXPECT_EQ(template_faces_check(template_1_3()), 6);
  EXPECT_EQ(template_faces_check(template_1_4()), 6);
  EXPECT_EQ(template_faces_check(template_1_5()), 6);
}

TEST(Templates, OneThirteenAndAdjustedTemplates) {
  EXPECT_EQ(template_1_13().children.size(), 13u);
  EXPECT_EQ(template_1_3_adjust1().children.size(), 3u);
  EXPECT_EQ(template_1_3_adjust2().children.size(), 3u);
  EXPECT_EQ(template_split_edges(template_1_13()), 0xF);
  EXPECT_EQ(template_split_edges(template_1_3_adjust1()), (1 << 0) | (1 << 2) | (1 << 4));
  EXPECT_EQ(template_split_edges(template_1_3_adjust2()), (1 << 0) | (1 << 6));
  const double sj13 = template_validate(template_1_13());
  EXPECT_NEAR(sj13, 0.3077, 1e-4);  // the thesis' L-shaped minimum
  EXPECT_NEAR(template_validate(template_1_3_adjust1()), 0.7537, 1e-4);
  EXPECT_GT(template_validate(template_1_3_adjust2()), 0.3077);
  EXPECT_EQ(template_faces_check(template_1_13()), 6);
  // The merged faces (y=1, z=1 for one adjustment; all four sides for two) are checked by the
  // conformity tests of templates_apply with face aliases.
  EXPECT_EQ(template_faces_check(template_1_3_adjust1(), {3, 5}), 4);
  EXPECT_EQ(template_faces_check(template_1_3_adjust2(), {2, 3, 4, 5}), 2);
}

TEST(Templates, OneThirteenInteriorHeightIsTheBestOfAScan) {
  double best = -1;
  for (int i = 1; i < 60; ++i) {
    double sj = -1;
    try {
      sj = template_validate(template_1_13_build(i / 60.0));
    } catch (const OperationError&) {
    }
    best = std::max(best, sj);
  }
  EXPECT_NEAR(best, 4.0 / 13.0, 1e-4);
  EXPECT_NEAR(template_validate(template_1_13()), best, 1e-12);
}

TEST(Templates, MaskTableCoversTheSevenPatternsUnderAllSymmetries) {
  int covered = 0;
  std::map<TemplateTag, int> per_tag;
  for (int m = 1; m < 4096; ++m) {
    const TemplateChoice c = template_for_mask(static_cast<uint16_t>(m));
    if (!c.tmpl) continue;
    ++covered;
    ++per_tag[c.tmpl->tag];
    EXPECT_EQ(cube_symmetry_edge_mask(cube_symmetries()[c.symmetry], template_split_edges(*c.tmpl)),
              m);
  }
  EXPECT_EQ(per_tag[TemplateTag::t1_27], 1);
  EXPECT_EQ(per_tag[TemplateTag::t1_13], 6);          // one per face
  EXPECT_EQ(per_tag[TemplateTag::t1_5], 12);          // one per edge
  EXPECT_EQ(per_tag[TemplateTag::t1_4], 6 * 2);       // two parallel edge pairs per face
  EXPECT_EQ(per_tag[TemplateTag::t1_3], 3);           // one per direction
  EXPECT_EQ(per_tag[TemplateTag::t1_3_adjust1], 12);  // three of four parallel edges
  EXPECT_EQ(per_tag[TemplateTag::t1_3_adjust2], 6);   // a diagonal pair per direction
  EXPECT_EQ(covered, 1 + 6 + 12 + 12 + 3 + 12 + 6);
  EXPECT_EQ(template_for_mask(0).tmpl, nullptr);
}

TEST(Templates, SheetDirectionalSetHasOneToNineAndNoAdjustments) {
  std::map<TemplateTag, int> per_tag;
  for (int m = 1; m < 4096; ++m) {
    const TemplateChoice c =
        template_for_mask(static_cast<uint16_t>(m), TemplateSet::sheet_directional);
    if (!c.tmpl) continue;
    ++per_tag[c.tmpl->tag];
    EXPECT_EQ(cube_symmetry_edge_mask(cube_symmetries()[c.symmetry], template_split_edges(*c.tmpl)),
              m);
  }
  EXPECT_EQ(per_tag[TemplateTag::t1_3], 3);
  EXPECT_EQ(per_tag[TemplateTag::t1_4], 12);
  EXPECT_EQ(per_tag[TemplateTag::t1_5], 12);
  EXPECT_EQ(per_tag[TemplateTag::t1_9], 3);  // one per pair of axes
  EXPECT_EQ(per_tag[TemplateTag::t1_27], 1);
  EXPECT_EQ(per_tag.count(TemplateTag::t1_13), 0u);
  EXPECT_EQ(per_tag.count(TemplateTag::t1_3_adjust1), 0u);
  EXPECT_EQ(template_1_9().children.size(), 9u);
  EXPECT_DOUBLE_EQ(template_validate(template_1_9()), 1.0);
}

TEST(Templates, TagNamesAreDistinct) {
  std::set<std::string> names;
  for (int t = 0; t < template_tag_count; ++t)
    names.insert(template_tag_name(static_cast<TemplateTag>(t)));
  EXPECT_EQ(names.size(), static_cast<size_t>(template_tag_count));
  EXPECT_STREQ(template_tag_name(TemplateTag::t1_3_adjust2), "1-3-adj2");
  EXPECT_STREQ(template_tag_name(static_cast<TemplateTag>(99)), "unknown");
}

TEST(Templates, CompiledPlansClassifyEveryNode) {
  // 1-27 in the identity: 8 corners, 24 edge nodes, 24 face nodes, 8 interior nodes; all on the
  // slot grid. 1-13: its interior nodes at 1/6 are off the slot grid only inside the cube.
  std::map<CubeEntity, int> count;
  for (const TemplatePlanNode& n : template_1_27().plans[0].nodes) ++count[n.entity];
  EXPECT_EQ(count[CubeEntity::corner], 8);
  EXPECT_EQ(count[CubeEntity::edge], 24);
  EXPECT_EQ(count[CubeEntity::face], 24);
  EXPECT_EQ(count[CubeEntity::interior], 8);
  for (const HexTemplate* t :
       {&template_1_27(), &template_1_13(), &template_1_5(), &template_1_4(), &template_1_3(),
        &template_1_9(), &template_1_3_adjust1(), &template_1_3_adjust2()}) {
    ASSERT_EQ(t->plans.size(), 48u);
    for (const TemplatePlan& p : t->plans) {
      EXPECT_TRUE(p.slotted) << template_tag_name(t->tag);
      for (const TemplatePlanNode& n : p.nodes) {
        EXPECT_FALSE(n.off_grid);
        double sum = 0;
        for (double w : n.weight) sum += w;
        EXPECT_NEAR(sum, 1.0, 1e-15);
      }
    }
  }
  // A node off the exact grid inside the cube is compiled as a private interior node; on the
  // cube's boundary it is refused.
  HexTemplate t = template_1_3();
  t.nodes.push_back({{0.3, 1.0 / 7.0, 0.5}});
  template_compile(t, 1);
  EXPECT_TRUE(t.plans[0].nodes.back().off_grid);
  t.nodes.back().ref = {0.0, 1.0 / 7.0, 0.5};
  EXPECT_THROW(template_compile(t, 1), OperationError);
}

TEST(Templates, ChildDirectionsFollowSheets) {
  // 1-3: every slab keeps the cube's axes.
  for (const auto& a : template_1_3().child_axis) EXPECT_EQ(a, (std::array<int8_t, 3>{0, 1, 2}));
  // 1-4 (x-edges of face y=0 split): the top child (Q1 Q2 C D) has two directions on x sheets
  // (the split edge's sheet turns round it) and none on the y sheet; the others keep x, y, z.
  const HexTemplate& t = template_1_4();
  int without_y = 0;
  for (size_t c = 0; c < t.children.size(); ++c) {
    const auto& a = t.child_axis[c];
    EXPECT_EQ(a[2], 2);
    const bool has_y = a[0] == 1 || a[1] == 1;
    if (!has_y) {
      ++without_y;
      EXPECT_EQ(a[0], 0);
      EXPECT_EQ(a[1], 0);
    }
  }
  EXPECT_EQ(without_y, 1);
  for (const HexTemplate* tp : {&template_1_5(), &template_1_3_adjust1(), &template_1_3_adjust2()})
    EXPECT_EQ(tp->child_axis.size(), tp->children.size());
}

TEST(Templates, ValidateRejectsAnInvertedChild) {
  HexTemplate t = template_1_3();
  std::swap(t.children[1][0], t.children[1][1]);
  EXPECT_THROW(template_validate(t), OperationError);
}

TEST(Templates, BasicTemplatesSubdivideAFaceAsAFunctionOfItsSplitEdges) {
  // The premise of the selective refiner's self-check (it rebuilds the topology only around
  // directional and adjusted hexes): any two basic-template faces with the same split sides,
  // in any symmetry and from either side (all 8 motions of the square), are subdivided alike.
  const HexTemplate* basic[] = {&template_1_27(), &template_1_13(), &template_1_5(),
                                &template_1_4(), &template_1_3()};
  std::map<int, std::set<Quad2>> pattern_of_mask;
  int faces = 0;
  for (const HexTemplate* t : basic) {
    for (int sym = 0; sym < 48; ++sym) {
      const CubeSymmetry& s = cube_symmetries()[sym];
      std::vector<std::array<long, 3>> p6;
      for (const TemplateNode& n : t->nodes) {
        const auto q = cube_symmetry_apply(s, n.ref);
        p6.push_back({std::lround(6 * q[0]), std::lround(6 * q[1]), std::lround(6 * q[2])});
      }
      for (int lf = 0; lf < 6; ++lf) {
        const int* o = hex_corner[hex_faces[lf][0]];
        const int* c1 = hex_corner[hex_faces[lf][1]];
        const int* c3 = hex_corner[hex_faces[lf][3]];
        const int axis = lf / 2;
        const long level = 6 * (lf % 2);
        auto to2 = [&](const std::array<long, 3>& p) {
          Point2 r{0, 0};
          for (int k = 0; k < 3; ++k) {
            r[0] += (c1[k] - o[k]) * (p[k] - 6 * o[k]);
            r[1] += (c3[k] - o[k]) * (p[k] - 6 * o[k]);
          }
          return r;
        };
        std::vector<Quad2> quads;
        for (auto c : t->children) {
          if (s.reflection) c = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
          for (int cf = 0; cf < 6; ++cf) {
            Quad2 q;
            bool on = true;
            for (int i = 0; i < 4; ++i) {
              on = on && p6[c[hex_faces[cf][i]]][axis] == level;
              q[i] = to2(p6[c[hex_faces[cf][i]]]);
            }
            if (on) quads.push_back(q);
          }
        }
        ASSERT_FALSE(quads.empty());
        ++faces;
        for (int motion = 0; motion < 8; ++motion) {
          std::set<Quad2> image;
          int mask = 0;
          for (Quad2 q : quads) {
            for (Point2& p : q) {
              long u = p[0], v = p[1];
              if (motion & 1) u = 6 - u;
              if (motion & 2) v = 6 - v;
              if (motion & 4) std::swap(u, v);
              p = {u, v};
              if (v == 0 && u > 0 && u < 6) mask |= 1;
              if (u == 6 && v > 0 && v < 6) mask |= 2;
              if (v == 6 && u > 0 && u < 6) mask |= 4;
              if (u == 0 && v > 0 && v < 6) mask |= 8;
            }
            image.insert(quad_sorted(q));
          }
          const auto [it, inserted] = pattern_of_mask.emplace(mask, image);
          EXPECT_EQ(it->second, image) << template_tag_name(t->tag) << " symmetry " << sym
                                       << " face " << lf << " motion " << motion;
        }
      }
    }
  }
  EXPECT_EQ(faces, 5 * 48 * 6);
  // Split sides met: none, one (4 ways), two opposite (2), all four.
  EXPECT_EQ(pattern_of_mask.size(), 8u);
}

}  // namespace
}  // namespace hexrefine
