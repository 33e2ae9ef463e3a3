// Light-tree builds and per-shading-point cost of the three light evaluators, without a
// scene (visibility = 1), over lights on the walls of a box (VPL-like: oriented, varied
// intensities) and omni lights in a volume.
// Run: build/bench/lightcuts_bench
#include <benchmark/benchmark.h>

#include <map>

#include "core/rng.h"
#include "lightcuts/evaluator.h"

namespace {

using namespace lc;
using namespace lc::lightcuts;

LightSet makeLights(size_t n, LightType type) {
  LightSet s;
  s.groups.push_back(LightGroup{});
  Rng r(4, 2);
  for (size_t i = 0; i < n; ++i) {
    Light l;
    l.type = type;
    if (type == LightType::Oriented) {
      int face = int(r.below(5));  // walls and ceiling of a 10-unit box, facing inward
      float u = r.uniform() * 10, v = r.uniform() * 10;
      switch (face) {
        case 0: l.position = Vec3(0, u, v); l.direction = Vec3(1, 0, 0); break;
        case 1: l.position = Vec3(10, u, v); l.direction = Vec3(-1, 0, 0); break;
        case 2: l.position = Vec3(u, v, 10); l.direction = Vec3(0, 0, -1); break;
        case 3: l.position = Vec3(u, 10, v); l.direction = Vec3(0, -1, 0); break;
        default: l.position = Vec3(u, v, 0); l.direction = Vec3(0, 0, 1); break;
      }
    } else {
      l.position = Vec3(r.uniform() * 10, 5 + r.uniform() * 5, r.uniform() * 10);
    }
    float I = 0.1f + r.uniform();
    l.intensity = Color(I * r.uniform(), I * r.uniform(), I * r.uniform()) * (100.0f / float(n));
    s.lights.push_back(l);
  }
  return s;
}

const LightSet& lightsFor(size_t n, LightType t) {
  static std::map<std::pair<size_t, int>, LightSet> cache;
  auto key = std::make_pair(n, int(t));
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, makeLights(n, t)).first;
  return it->second;
}

void TreeBuild(benchmark::State& state) {
  const LightSet& s = lightsFor(size_t(state.range(0)), LightType(state.range(1)));
  TreeBuildOptions o;
  o.builder = state.range(2) ? TreeBuilder::Course : TreeBuilder::Agglomerative;
  for (auto _ : state) benchmark::DoNotOptimize(buildLightForest(s, o));
  state.SetLabel(std::string(lightTypeName(LightType(state.range(1)))) + (state.range(2) ? " seed" : " walter"));
  state.counters["lights/s"] = benchmark::Counter(double(state.range(0)) * double(state.iterations()), benchmark::Counter::kIsRate);
}

struct Unoccluded : Visibility {
  Color operator()(const Vec3&, float) override { return Color(1); }
};

void Evaluate(benchmark::State& state) {
  size_t n = size_t(state.range(0));
  const LightSet& s = lightsFor(n, LightType::Oriented);
  static std::map<size_t, LightForest> forests;
  if (!forests.count(n)) forests[n] = buildLightForest(s);
  Method m = Method(state.range(1));
  std::unique_ptr<LightEvaluator> ev = m == Method::Brute     ? makeBruteForce(s)
                                       : m == Method::Course    ? makeCourseCuts(s, forests[n], CutOptions{0.5f, 1000})
                                                              : makeLightcuts(s, forests[n], CutOptions{});
  Rng r(9, 9);
  std::vector<ShadingPoint> pts(256);
  for (ShadingPoint& sp : pts) {
    sp.p = Vec3(0.5f + 9 * r.uniform(), 0.01f, 0.5f + 9 * r.uniform());
    sp.n = Vec3(0, 1, 0);
    sp.r = normalize(Vec3(r.uniform() - 0.5f, 1, r.uniform() - 0.5f));
    sp.kd = Color(0.7f);
  }
  Unoccluded vis;
  EvalStats st;
  for (auto _ : state)
    for (const ShadingPoint& sp : pts) benchmark::DoNotOptimize(ev->evaluate(sp, vis, st));
  state.counters["points/s"] = benchmark::Counter(double(st.shadingPoints), benchmark::Counter::kIsRate);
  state.counters["cut"] = double(st.cutNodes) / double(std::max<uint64_t>(1, st.shadingPoints));
  state.SetLabel(methodName(m));
}

BENCHMARK(TreeBuild)
    ->ArgsProduct({{1000, 10000, 100000, 1000000}, {int(LightType::Omni), int(LightType::Oriented)}, {0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(TreeBuild)->ArgsProduct({{100000}, {int(LightType::Oriented)}, {1}})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Evaluate)
    ->ArgsProduct({{1000, 10000, 100000}, {int(Method::Lightcuts), int(Method::Course)}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(Evaluate)->ArgsProduct({{1000, 10000}, {int(Method::Brute)}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
