// OccluderIndex: a "clear" answer must hold for every segment (checked with Embree against
// random scenes of every shape kind), and the cases it exists for must come out clear.
#include "scene/occluders.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <memory>

#include "core/rng.h"
#include "scene/scene.h"
#include "test_scenes.h"

namespace lc::scene {
namespace {

using io::ShapeKind;

io::ObjectDesc object(ShapeKind kind, const Mat4& m) { return testing::primitive(kind, m, 1.5f, 0.8f, 0.3f); }

Vec3 uniformIn(Rng& rng, const Vec3& lo, const Vec3& hi) {
  return lo + (hi - lo) * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
}

// Adds to d `count` shapes, of each kind in turn, centred within `spread` of the origin,
// scaled by `minScale` plus up to 1 along each axis and turned about a random axis (only
// every other one unless `turnAll`: shapes aligned with the world's axes are a case of
// their own).
void addRandomShapes(io::SceneDesc& d, Rng& rng, int count, float spread, float minScale, bool turnAll) {
  for (int k = 0; k < count; ++k) {
    Vec3 c = uniformIn(rng, Vec3(-spread), Vec3(spread));
    Mat4 m = Mat4::translate(c.x, c.y, c.z) *
             (turnAll || k % 2 ? Mat4::rotate(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5,
                                              6.28 * rng.uniform())
                               : Mat4::identity()) *
             Mat4::scale(minScale + rng.uniform(), minScale + rng.uniform(), minScale + rng.uniform());
    d.objects.push_back(object(ShapeKind(k % 5), m));
  }
}

// Adds to d one mesh object of `count` random triangles, each with its corners within
// `size` of a centre in [-spread, spread]^3.
void addRandomTriangles(io::SceneDesc& d, Rng& rng, int count, float spread, float size) {
  io::MeshDesc mesh;
  for (int t = 0; t < count; ++t) {
    Vec3 c = uniformIn(rng, Vec3(-spread), Vec3(spread));
    for (int v = 0; v < 3; ++v) mesh.points.push_back(c + uniformIn(rng, Vec3(-size), Vec3(size)));
    mesh.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  io::ObjectDesc mo = object(ShapeKind::Mesh, Mat4::identity());
  mo.mesh = int(d.meshes.size());
  d.meshes.push_back(std::move(mesh));
  d.objects.push_back(mo);
}

// A scene of `shapes` random shapes (addRandomShapes) and `triangles` random triangles of
// up to a unit's size, all within `spread` of the origin.
struct RandomScene {
  io::SceneDesc desc;
  std::unique_ptr<Scene> scene;
};
RandomScene randomScene(Rng& rng, int shapes, float spread, float minScale, bool turnAll, int triangles) {
  RandomScene r;
  r.desc.materials.emplace_back();
  addRandomShapes(r.desc, rng, shapes, spread, minScale, turnAll);
  addRandomTriangles(r.desc, rng, triangles, spread, 1.0f);
  r.scene = Scene::build(r.desc);
  return r;
}

// Whether a "clear" answer holds: the segments from the apex to the box's corners and to
// `samples - 8` random points in it, each stopping `shortfall` short, meet no surface.
::testing::AssertionResult segmentsClear(const Scene& s, Rng& rng, const Vec3& apex, const Vec3& c, const Vec3& h,
                                         float shortfall, int samples) {
  for (int k = 0; k < samples; ++k) {
    Vec3 target = k < 8 ? Vec3((k & 1) ? c.x + h.x : c.x - h.x, (k & 2) ? c.y + h.y : c.y - h.y,
                               (k & 4) ? c.z + h.z : c.z - h.z)
                        : uniformIn(rng, c - h, c + h);
    Vec3 dir = target - apex;
    float dist = length(dir);
    if (!(dist > shortfall)) continue;
    if (s.occluded(apex, dir / dist, dist - shortfall))
      return ::testing::AssertionFailure() << "called clear, but a segment meets a surface";
  }
  return ::testing::AssertionSuccess();
}

// Random scenes: a few shapes of every kind under random rotations and scales, and a
// mesh of random triangles; random apexes and boxes. Every "clear" is checked with rays
// to the box's corners and random points in it; enough answers must be "clear" for the
// check to mean something, and enough "not clear" for the test to discriminate.
TEST(OccluderIndex, ClearSegmentsMeetNoSurface) {
  Rng rng(21, 0);
  int clear = 0, blocked = 0;
  for (int sceneIndex = 0; sceneIndex < 12; ++sceneIndex) {
    const RandomScene r = randomScene(rng, 6, 4.0f, 0.3f, true, 6);
    const Scene& s = *r.scene;
    const OccluderIndex& index = s.occluders();
    ASSERT_EQ(index.pieceCount(), 6u + 6u);
    for (int q = 0; q < 300; ++q) {
      Vec3 apex = uniformIn(rng, Vec3(-6.0f), Vec3(6.0f));
      Vec3 c = uniformIn(rng, Vec3(-6.0f), Vec3(6.0f)), h = uniformIn(rng, Vec3(0.0f), Vec3(0.6f));
      const float shortfall = q % 2 ? 0.0f : 0.01f;
      if (!index.clear(apex, c - h, c + h, 1e-5f, shortfall)) {
        ++blocked;
        continue;
      }
      ++clear;
      ASSERT_TRUE(segmentsClear(s, rng, apex, c, h, shortfall, 72)) << "scene " << sceneIndex << " query " << q;
    }
  }
  EXPECT_GT(clear, 300);
  EXPECT_GT(blocked, 300);
}

// A room of thin boxes with a pillar: from a point on the floor a box of lights under the
// ceiling in the open is clear; one behind the pillar is not.
TEST(OccluderIndex, RoomInteriorIsClearPillarIsNot) {
  io::SceneDesc d;
  d.materials.emplace_back();
  auto slab = [&](Vec3 c, Vec3 size) {
    d.objects.push_back(object(ShapeKind::Box, Mat4::translate(c.x, c.y, c.z) * Mat4::scale(size.x, size.y, size.z)));
  };
  slab({0, -0.05f, 0}, {10, 0.1f, 10});  // floor, top at y = 0
  slab({0, 4.05f, 0}, {10, 0.1f, 10});   // ceiling
  slab({-5.05f, 2, 0}, {0.1f, 4, 10});
  slab({5.05f, 2, 0}, {0.1f, 4, 10});
  slab({0, 2, -5.05f}, {10, 4, 0.1f});
  slab({0, 2, 5.05f}, {10, 4, 0.1f});
  slab({2, 2, 0}, {0.5f, 4, 0.5f});  // a pillar
  auto s = Scene::build(d);
  const float eps = s->epsilon();
  const Vec3 apex(0, eps, 0);  // just above the floor
  EXPECT_TRUE(s->occluders().clear(apex, Vec3(-3, 3, -3), Vec3(-2, 3.5f, -2), 0.1f * eps));
  EXPECT_FALSE(s->occluders().clear(apex, Vec3(3.5f, 1, -0.5f), Vec3(4.5f, 2, 0.5f), 0.1f * eps));
  // A box that reaches into the ceiling is not clear.
  EXPECT_FALSE(s->occluders().clear(apex, Vec3(-3, 3, -3), Vec3(-2, 4.2f, -2), 0.1f * eps));
}

// A row of lights (a string, a strip) seen from a point: the segments to it fill a thin
// wedge. A box beside the wedge overlaps its bounding box on every axis, and the cone around
// a row that long is too wide to use; only the wedge's own faces (the planes through the
// point and the row's silhouette edges) set it apart. A box in the wedge is not apart.
// The row spans x in [-3, 3] at y in [3, 3.1], z in [-halfDepth, halfDepth].
void expectWedgeSetsTheBoxBesideApart(float halfDepth) {
  auto sceneWith = [](Vec3 c) {
    io::SceneDesc d;
    d.materials.emplace_back();
    d.objects.push_back(object(ShapeKind::Box, Mat4::translate(c.x, c.y, c.z) * Mat4::scale(0.3f, 0.3f, 0.1f)));
    return Scene::build(d);
  };
  const Vec3 apex(0, 0, 0), lo(-3, 3, -halfDepth), hi(3, 3.1f, halfDepth);
  auto beside = sceneWith(Vec3(2.5f, 0.5f, 0));
  EXPECT_TRUE(beside->occluders().clear(apex, lo, hi, 1e-5f));
  auto inside = sceneWith(Vec3(0.2f, 1.5f, 0));
  EXPECT_FALSE(inside->occluders().clear(apex, lo, hi, 1e-5f));
  // Every segment to the row misses the box beside it, and some meet the one inside.
  int met = 0;
  for (int k = 0; k <= 60; ++k) {
    const Vec3 target(-3 + 0.1f * float(k), 3.05f, 0);
    const float dist = length(target - apex);
    EXPECT_FALSE(beside->occluded(apex, (target - apex) / dist, dist));
    met += inside->occluded(apex, (target - apex) / dist, dist);
  }
  EXPECT_GT(met, 0);
}

TEST(OccluderIndex, ABoxBesideTheWedgeToARowOfLightsIsApart) { expectWedgeSetsTheBoxBesideApart(0.1f); }

// The same wedge to a row of lights with no thickness at all (lights on a plane): the
// hull's side faces run through the apex and the row's ends, along the row's flat
// direction; a box beside the wedge is apart from them (an edge of no length gave no plane).
TEST(OccluderIndex, AFlatRowOfLightsKeepsTheWedgesSideFaces) { expectWedgeSetsTheBoxBesideApart(0.0f); }

// A wall's lights make a box as thin as their coordinates' rounding (559.2 +- one ulp).
// Its edges across that thickness are a ten-thousandth of a unit long: a plane through the
// apex and such an edge takes its direction from rounding, and the Cornell box's ceiling
// saw a garbage plane that left the box's far corners 2.5 units outside it. A piece in
// the hull beyond that plane (here halfway from the apex to such a corner) was set apart,
// and lights behind the tall block were counted visible. The planes' offsets now bound
// the box as computed, whatever the edge.
TEST(OccluderIndex, ANearlyFlatBoxGivesNoFalsePlanes) {
  const Vec3 apex(554.265869f, 260.986328f, 7.51021242f);
  const Vec3 c(208.84201f, 408.202271f, 559.200012f), h(206.841919f, 135.487549f, 6.10351562e-05f);
  const Vec3 corner(c.x + h.x, c.y + h.y, c.z);
  const Vec3 mid = (apex + corner) * 0.5f;
  io::SceneDesc d;
  d.materials.emplace_back();
  d.objects.push_back(object(ShapeKind::Box, Mat4::translate(mid.x, mid.y, mid.z) * Mat4::scale(0.5f, 0.5f, 0.5f)));
  auto s = Scene::build(d);
  const Vec3 dir = corner - apex;
  ASSERT_TRUE(s->occluded(apex, dir / length(dir), length(dir)));
  EXPECT_FALSE(s->occluders().clear(apex, c - h, c + h, 1e-3f));
}

// Lights on a surface (VPLs, an emitter's samples): the segments end short of them, so the
// surface they lie on is apart from the segments though the box touches it.
TEST(OccluderIndex, ShortfallSetsApartTheSurfaceTheLightsLieOn) {
  io::SceneDesc d;
  d.materials.emplace_back();
  // A square in the plane y = 3 (local z = 0 turned to face -y), 4 x 4.
  d.objects.push_back(object(ShapeKind::Square, Mat4::translate(0, 3, 0) * Mat4::rotate(1, 0, 0, 1.5707963) *
                                                     Mat4::scale(4, 4, 1)));
  auto s = Scene::build(d);
  const Vec3 apex(0, 0, 0), lo(-1, 3, -1), hi(1, 3, 1);
  EXPECT_FALSE(s->occluders().clear(apex, lo, hi, 1e-5f, 0.0f));
  EXPECT_TRUE(s->occluders().clear(apex, lo, hi, 1e-5f, 1e-3f));
  // From either side: a box reaching behind the surface by more than the shortfall is not
  // clear, one in front of it is.
  const Vec3 below(0, 0, 0), above(0, 6, 0);
  EXPECT_FALSE(s->occluders().clear(below, Vec3(-1, 3, -1), Vec3(1, 3.01f, 1), 1e-5f, 1e-3f));
  EXPECT_TRUE(s->occluders().clear(below, Vec3(-1, 2.99f, -1), Vec3(1, 3, 1), 1e-5f, 1e-3f));
  EXPECT_FALSE(s->occluders().clear(above, Vec3(-1, 2.99f, -1), Vec3(1, 3, 1), 1e-5f, 1e-3f));
  EXPECT_TRUE(s->occluders().clear(above, Vec3(-1, 3, -1), Vec3(1, 3.01f, 1), 1e-5f, 1e-3f));
}

// The shape the apex lies on may be left out by the caller (a convex shape, the box in
// front of its tangent plane); without that the point's own sphere stands in the way.
TEST(OccluderIndex, SkipLeavesOutTheApexsOwnShape) {
  io::SceneDesc d;
  d.materials.emplace_back();
  d.objects.push_back(object(ShapeKind::Sphere, Mat4::identity()));
  auto s = Scene::build(d);
  // On the sphere at 45 degrees, inside its bounding cube; the box along the normal.
  const Vec3 apex(0.7072f, 0.7072f, 0), lo(2.7f, 2.7f, -0.3f), hi(3.3f, 3.3f, 0.3f);
  EXPECT_FALSE(s->occluders().clear(apex, lo, hi, 1e-5f));
  EXPECT_TRUE(s->occluders().clear(apex, lo, hi, 1e-5f, 0.0f, 0));
}

// The hint: the piece that said no is remembered and tried first; answers do not change.
TEST(OccluderIndex, HintKeepsTheBlockerAndTheAnswers) {
  io::SceneDesc d;
  d.materials.emplace_back();
  for (int k = 0; k < 20; ++k)
    d.objects.push_back(object(ShapeKind::Box, Mat4::translate(3.0 * k, 0, 0)));
  auto s = Scene::build(d);
  uint32_t hint = ~0u;
  EXPECT_FALSE(s->occluders().clear(Vec3(30, 0, -5), Vec3(29.5f, -0.2f, 4), Vec3(30.5f, 0.2f, 5), 1e-5f, 0, -1, &hint));
  EXPECT_LT(hint, s->occluders().pieceCount());
  const uint32_t blocker = hint;
  EXPECT_FALSE(s->occluders().clear(Vec3(30, 0, -5), Vec3(29.8f, -0.1f, 4), Vec3(30.2f, 0.1f, 5), 1e-5f, 0, -1, &hint));
  EXPECT_EQ(hint, blocker);
  EXPECT_TRUE(s->occluders().clear(Vec3(31.5f, 0, -5), Vec3(31.4f, -0.1f, 4), Vec3(31.6f, 0.1f, 5), 1e-5f, 0, -1,
                                   &hint));
}

// Any piece as the hint, the answer is the one without a hint. A hinted piece is first
// asked whether a segment toward a corner of the box runs through it (a "no" before the hull
// is set up); random scenes of every shape kind, rotated and scaled, and random triangles,
// with random apexes, boxes, shortfalls and skipped shapes, and boxes of lights lying on a
// triangle (which the shortfall sets apart), check that it never says no where the full test
// says clear.
TEST(OccluderIndex, AHintNeverChangesTheAnswer) {
  Rng rng(33, 0);
  int clear = 0, blocked = 0;
  for (int sceneIndex = 0; sceneIndex < 8; ++sceneIndex) {
    const RandomScene r = randomScene(rng, 10, 3.0f, 0.2f, false, 4);
    const OccluderIndex& index = r.scene->occluders();
    const io::MeshDesc& mesh = r.desc.meshes.back();
    for (int q = 0; q < 200; ++q) {
      Vec3 apex = uniformIn(rng, Vec3(-5.0f), Vec3(5.0f));
      Vec3 c = uniformIn(rng, Vec3(-5.0f), Vec3(5.0f)), h = uniformIn(rng, Vec3(0.0f), Vec3(1.0f));
      if (q % 7 == 0) h.y = 0;  // flat boxes too
      if (q % 4 == 3) {
        // Lights on a triangle, seen from in front of it: the segments end short of it.
        const auto& t = mesh.triangles[size_t(q / 4) % mesh.triangles.size()];
        const Vec3 a = mesh.points[size_t(t[0])], b = mesh.points[size_t(t[1])], e = mesh.points[size_t(t[2])];
        c = (a + b + e) / 3.0f;
        h = Vec3(0.02f);
        apex = c + normalize(cross(b - a, e - a)) * (0.5f + 2 * rng.uniform());
      }
      const float shortfall = q % 3 == 0 ? 0.0f : q % 3 == 1 ? 0.01f : 0.5f;
      const int skip = q % 5 == 0 ? int(rng.uniform() * 10) : -1;
      const bool expected = index.clear(apex, c - h, c + h, 1e-5f, shortfall, skip);
      (expected ? clear : blocked) += 1;
      for (uint32_t piece = 0; piece < index.pieceCount(); ++piece) {
        uint32_t hint = piece;
        ASSERT_EQ(index.clear(apex, c - h, c + h, 1e-5f, shortfall, skip, &hint), expected)
            << "scene " << sceneIndex << " query " << q << " hint " << piece;
      }
    }
  }
  EXPECT_GT(clear, 100);
  EXPECT_GT(blocked, 400);
}

// A mesh of more triangles than kParallelPieces: its hierarchy is built in parallel, into
// slots fixed by the piece counts. Its answers must be sound (no "clear" segment meets a
// triangle) and the same whatever the number of threads that built it.
TEST(OccluderIndex, ALargeMeshBuiltInParallelAnswersSoundlyAndAlike) {
  Rng rng(5, 0);
  io::SceneDesc d;
  d.materials.emplace_back();
  addRandomTriangles(d, rng, 40000, 50.0f, 0.4f);
  std::unique_ptr<Scene> one, all;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = Scene::build(d);
  }
  all = Scene::build(d);
  ASSERT_EQ(all->occluders().pieceCount(), 40000u);
  int clear = 0, blocked = 0;
  for (int q = 0; q < 2000; ++q) {
    Vec3 apex = uniformIn(rng, Vec3(-50.0f), Vec3(50.0f));
    Vec3 c = apex + uniformIn(rng, Vec3(-6.0f), Vec3(6.0f)), h = uniformIn(rng, Vec3(0.0f), Vec3(0.5f));
    const bool answer = all->occluders().clear(apex, c - h, c + h, 1e-5f);
    ASSERT_EQ(answer, one->occluders().clear(apex, c - h, c + h, 1e-5f)) << "query " << q;
    if (!answer) {
      ++blocked;
      continue;
    }
    ++clear;
    ASSERT_TRUE(segmentsClear(*all, rng, apex, c, h, 0.0f, 24)) << "query " << q;
  }
  EXPECT_GT(clear, 200);
  EXPECT_GT(blocked, 200);
}

}  // namespace
}  // namespace lc::scene
