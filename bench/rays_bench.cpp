// Ray throughput of the Embree scene: closest-hit camera rays and incoherent occlusion
// (shadow) rays, single-threaded, on the Cornell box and on a generated ~1M-triangle mesh;
// and the occluder index's clear tests on the same scenes.
// Run: build/bench/rays_bench
#include <benchmark/benchmark.h>

#include <cmath>

#include "core/rng.h"
#include "io/ray_parser.h"
#include "scene/scene.h"

namespace {

using namespace lc;

std::unique_ptr<scene::Scene> cornellBox() {
  io::SceneDesc d = io::parseRayFile(std::string(LC_SOURCE_DIR) + "/scenes/cornell_box.ray");
  for (auto& m : d.materials) m.luminosity.reset();  // geometry only
  return scene::Scene::build(d);
}

// A bumpy sphere tessellated into 2 * n * n triangles (n = 708: about 1M).
std::unique_ptr<scene::Scene> bigMesh(int n) {
  io::SceneDesc d;
  d.materials.emplace_back();
  d.materials[0].diffuse.value = Color(0.7f);
  io::MeshDesc m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float th = kPi * float(j) / float(n), ph = 2 * kPi * float(i) / float(n);
      float r = 1 + 0.05f * std::sin(13 * th) * std::cos(17 * ph);
      m.points.emplace_back(r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, e = c + 1;
      m.triangles.push_back({a, c, b});
      m.triangles.push_back({b, c, e});
    }
  d.meshes.push_back(std::move(m));
  io::ObjectDesc o;
  o.kind = io::ShapeKind::Mesh;
  o.mesh = 0;
  d.objects.push_back(o);
  d.camera.position = Vec3(0, 0, 3);
  d.camera.viewDir = Vec3(0, 0, -1);
  return scene::Scene::build(d);
}

const scene::Scene& sceneFor(int which) {
  static auto cb = cornellBox();
  static auto mesh = bigMesh(708);
  return which == 0 ? *cb : *mesh;
}

void PrimaryRays(benchmark::State& state) {
  const scene::Scene& s = sceneFor(int(state.range(0)));
  const scene::Camera& cam = s.camera();
  const int W = 256;
  int64_t rays = 0, hits = 0;
  for (auto _ : state) {
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) {
        scene::Hit h;
        hits += s.intersect(scene::Ray{cam.eye, normalize(cam.direction((x + 0.5f) / W, (y + 0.5f) / W)), 0, kInf}, h);
      }
    rays += W * W;
  }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["hit fraction"] = double(hits) / double(std::max<int64_t>(rays, 1));
  state.SetLabel(state.range(0) == 0 ? "cornell box" : "1M-triangle mesh");
}

// Occlusion rays between random points inside the scene's bounds: incoherent, like the
// shadow rays of a many-light render.
void ShadowRays(benchmark::State& state) {
  const scene::Scene& s = sceneFor(int(state.range(0)));
  Bounds3 b = s.bounds();
  Rng rng(1, 2);
  const int N = 65536;
  std::vector<std::pair<Vec3, Vec3>> seg(N);
  for (auto& [p, q] : seg) {
    p = b.lo + b.extent() * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    q = b.lo + b.extent() * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
  }
  int64_t rays = 0, blocked = 0;
  for (auto _ : state) {
    for (auto& [p, q] : seg) {
      Vec3 d = q - p;
      float len = length(d);
      blocked += s.occluded(p, d / len, len);
    }
    rays += N;
  }
  state.counters["rays/s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["blocked fraction"] = double(blocked) / double(std::max<int64_t>(rays, 1));
  state.SetLabel(state.range(0) == 0 ? "cornell box" : "1M-triangle mesh");
}

// The occluder index's clear test (scene/occluders.h, lightcuts' clear clusters) between
// the same random points and random boxes around the second one (up to a tenth of the
// scene's size): what a test costs beside a shadow ray, and how often it passes.
void ClearTests(benchmark::State& state) {
  const scene::Scene& s = sceneFor(int(state.range(0)));
  Bounds3 b = s.bounds();
  Rng rng(1, 2);
  const int N = 65536;
  struct Query {
    Vec3 apex, lo, hi;
  };
  std::vector<Query> qs(N);
  for (auto& q : qs) {
    q.apex = b.lo + b.extent() * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    Vec3 c = b.lo + b.extent() * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    Vec3 h = b.extent() * 0.05f * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    q.lo = c - h;
    q.hi = c + h;
  }
  const float margin = 0.1f * s.epsilon();
  int64_t tests = 0, passed = 0;
  for (auto _ : state) {
    uint32_t hint = ~0u;
    for (const Query& q : qs) passed += s.occluders().clear(q.apex, q.lo, q.hi, margin, 0, -1, &hint);
    tests += N;
  }
  state.counters["tests/s"] = benchmark::Counter(double(tests), benchmark::Counter::kIsRate);
  state.counters["clear fraction"] = double(passed) / double(std::max<int64_t>(tests, 1));
  state.SetLabel(state.range(0) == 0 ? "cornell box" : "1M-triangle mesh");
}

BENCHMARK(PrimaryRays)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(ShadowRays)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(ClearTests)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
