// Throughput of the workspace atlas (issue 11): items per second (IK,
// compliance, joint-space modes, a zero-order stability diagram over 100
// spindle speeds) on 1 and 2 threads, items dealt dynamically from an atomic
// counter as `robomill atlas` does, on examples/003_kr270_atlas.yaml (75
// items). Parallel efficiency at 2 = rate(2) / (2 rate(1)).

#include <benchmark/benchmark.h>

#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/io/job.hpp"

namespace {

using namespace robomill;

struct Setup {
  io::Job job = io::load_job(std::filesystem::path(__FILE__).parent_path().parent_path() /
                             "examples" / "003_kr270_atlas.yaml");
  robot::RobotModel robot{job.robot->description};
  atlas::AtlasContext context{
      *job.atlas,
      robot,
      Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(), robot.dof()),
      tool::Tool(*job.tool),
      job.cutting,
      job.process};
};

void BM_AtlasItems(benchmark::State& state) {
  static const Setup s;
  const int threads = static_cast<int>(state.range(0));
  const std::int64_t n = atlas::item_count(*s.job.atlas);
  std::vector<double> sink(static_cast<std::size_t>(n));
  for (auto _ : state) {
    std::atomic<std::int64_t> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      pool.emplace_back([&] {
        for (std::int64_t i; (i = next.fetch_add(1)) < n;)
          sink[static_cast<std::size_t>(i)] =
              s.context.evaluate(atlas::item(*s.job.atlas, i)).depth_min_m;
      });
    }
    for (std::thread& t : pool)
      t.join();
    benchmark::DoNotOptimize(sink.data());
  }
  state.counters["items_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations() * n), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AtlasItems)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
