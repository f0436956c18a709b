// Throughput of the Z-map (surface/topography.hpp): node tests ("Z-map cell
// updates": a node's height compared with the tool surface and lowered if
// above) per second, DESIGN.md §6, and the wall time of 001's 2 mm x 2 mm
// patch for case 5 (lead 10°, tilt 5°, runout 20 µm, no vibration) on the
// paper's 100 x 100 grid and a 400 x 400 one, with fz 0.25 mm (Table 2's
// feed read as 3000 mm/min, examples/001_case_5_surface.yaml) and, as a
// denser raster, fz 0.025 mm (the 300 mm/min reading, on its Eq 29 grid).

#include <benchmark/benchmark.h>

#include <numbers>

#include "robomill/surface/topography.hpp"

namespace {

using namespace robomill;
constexpr double kDeg = std::numbers::pi / 180.0;

void BM_ZMapCase5(benchmark::State& state) {
  tool::ToolSpec spec;
  spec.type = tool::ToolType::ball;
  spec.diameter_m = 8e-3;
  spec.teeth = 2;
  spec.helix_rad = 45.0 * kDeg;
  spec.overhang_m = 25e-3;
  spec.runout.offset_m = 0.02e-3;
  const tool::Tool tool(spec);
  surface::ToolOrientation orientation;
  orientation.lead_rad = 10.0 * kDeg;
  orientation.tilt_rad = 5.0 * kDeg;
  surface::RasterPath path;
  path.spindle_rad_s = 6000.0 * 2.0 * std::numbers::pi / 60.0;
  path.feed_per_tooth_m = static_cast<double>(state.range(2)) * 1e-6;
  path.stepover_m = 0.1e-3;
  path.passes = 29;
  path.first_pass_y_m = -0.4e-3;
  // Through the patch and beyond it by the evaluated band and a revolution's feed.
  path.x_start_m = -0.4e-3 - 2.0 * path.feed_per_tooth_m;
  path.x_end_m = 2.4e-3 + 2.0 * path.feed_per_tooth_m;
  surface::ZMapGrid grid;
  grid.length_x_m = grid.length_y_m = 2e-3;
  grid.cells_x = grid.cells_y = static_cast<int>(state.range(0));
  surface::ZMapOptions options;
  options.threads = static_cast<int>(state.range(1));
  long long tests = 0, points = 0;
  for (auto _ : state) {
    const auto result = surface::cut_zmap(tool, 0.5e-3, orientation, path, grid, {}, options);
    tests += result.stats.node_tests;
    points += result.stats.point_evaluations;
    benchmark::DoNotOptimize(result.map.z_m.data());
  }
  state.SetItemsProcessed(tests);
  state.counters["edge_points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["nodes"] = static_cast<double>(grid.node_count());
}
BENCHMARK(BM_ZMapCase5)
    ->ArgNames({"cells", "threads", "fz_um"})
    ->Args({100, 1, 250})
    ->Args({400, 1, 250})
    ->Args({400, 2, 250})
    ->Args({400, 1, 25})
    ->Args({400, 2, 25})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
