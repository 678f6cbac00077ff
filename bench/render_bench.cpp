// Rasterizer vs ray caster vs hybrid on the bundled scenes, one frame per
// iteration, at a fixed size and sample count. Compare ratios within one
// run: the machines this runs on are shared and noisy.
//   render_bench --benchmark_filter=cornell   (one scene)
//   RASTRAY_BENCH_THREADS=1 render_bench      (thread count; default: all)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "common/analysis.h"
#include "common/camera.h"
#include "common/gltf/loader.h"
#include "common/scene.h"
#include "raster/rasterizer.h"
#include "raytrace/ray_caster.h"

namespace rastray {
namespace {

constexpr int kWidth = 320, kHeight = 240, kSpp = 4;

struct Loaded {
  Scene scene;
  SceneAnalysis analysis;
  Camera camera;
};

const Loaded& load(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Loaded>> cache;
  auto& slot = cache[name];
  if (!slot) {
    slot = std::make_unique<Loaded>();
    slot->scene = loadScene(std::string(RASTRAY_SCENES) + "/" + name + ".gltf");
    slot->analysis = analyzeScene(slot->scene);
    slot->camera = makeCamera(slot->scene, {}, kWidth, kHeight);
  }
  return *slot;
}

void rasterFrame(benchmark::State& state, const std::string& name) {
  const Loaded& l = load(name);
  RasterOptions o;
  o.spp = kSpp;
  for (auto _ : state) benchmark::DoNotOptimize(renderRaster(l.scene, l.analysis, l.camera, o));
  state.SetLabel(std::to_string(kWidth) + "x" + std::to_string(kHeight) + " " + std::to_string(kSpp) +
                 " spp");
}

void raytraceFrame(benchmark::State& state, const std::string& name) {
  const Loaded& l = load(name);
  RayOptions o;
  o.spp = kSpp;
  for (auto _ : state) {
    RayCaster caster(l.scene, l.analysis);  // BVH build is part of the frame
    caster.bind(l.camera, o);
    benchmark::DoNotOptimize(caster.render());
  }
  state.SetLabel(std::to_string(kWidth) + "x" + std::to_string(kHeight) + " " + std::to_string(kSpp) +
                 " spp");
}

void hybridFrame(benchmark::State& state, const std::string& name) {
  const Loaded& l = load(name);
  RasterOptions ro;
  ro.spp = kSpp;
  ro.shadows = RasterShadows::Traced;
  RayOptions yo;
  yo.spp = kSpp;
  for (auto _ : state) {
    RayCaster caster(l.scene, l.analysis);
    caster.bind(l.camera, yo);
    benchmark::DoNotOptimize(renderRaster(l.scene, l.analysis, l.camera, ro, &caster, &caster));
  }
  state.SetLabel(std::to_string(kWidth) + "x" + std::to_string(kHeight) + " " + std::to_string(kSpp) +
                 " spp");
}

void registerAll() {
  for (const char* name : {"three-triangles", "cornell-box", "transparent-layers", "textured-plane"}) {
    const std::string n = name;
    benchmark::RegisterBenchmark(("raster/" + n).c_str(), [n](benchmark::State& s) { rasterFrame(s, n); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("raytrace/" + n).c_str(), [n](benchmark::State& s) { raytraceFrame(s, n); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("hybrid/" + n).c_str(), [n](benchmark::State& s) { hybridFrame(s, n); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
}

}  // namespace
}  // namespace rastray

int main(int argc, char** argv) {
  std::unique_ptr<tbb::global_control> threads;
  if (const char* t = std::getenv("RASTRAY_BENCH_THREADS"))
    threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                    size_t(std::max(1, std::atoi(t))));
  rastray::registerAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
