// Throughput of the workspace atlas (issue 11): items per second (IK,
// compliance, joint-space modes, a zero-order stability diagram over 100
// spindle speeds) on 1 and 2 threads, items dealt dynamically from an atomic
// counter as `robomill atlas` does, on examples/003_kr270_atlas.yaml (75
// items). Parallel efficiency at 2 = rate(2) / (2 rate(1)). Also the store's
// commit throughput (results rows per second in batches of 1000).

#include <benchmark/benchmark.h>

#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include "robomill/atlas/atlas.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/job/job.hpp"

namespace {

using namespace robomill;

struct Setup {
  job::Job job = job::load_job(std::filesystem::path(__FILE__).parent_path().parent_path() /
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

void BM_StoreCommit(benchmark::State& state) {
  atlas::AtlasSpec spec;
  spec.counts = {1000, 1000, 1};
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "robomill_bench_atlas.sqlite";
  for (const char* suffix : {"", "-wal"})
    std::filesystem::remove(file.string() + suffix);
  atlas::StoreIdentity identity;
  identity.job_text = "bench";
  identity.job_hash = atlas::fnv1a_hex(identity.job_text);
  identity.dof = 6;
  atlas::AtlasStore store(file, identity, spec, false);
  atlas::AtlasResult r;
  r.reachable = true;
  r.q = Eigen::VectorXd::Constant(6, 0.5);
  std::vector<std::pair<std::int64_t, atlas::AtlasResult>> batch;
  std::int64_t next = 0;
  for (auto _ : state) {
    batch.clear();
    for (int i = 0; i < 1000 && next < 1000000; ++i)
      batch.emplace_back(next++, r);
    store.commit(batch);
  }
  state.counters["rows_per_s"] = benchmark::Counter(static_cast<double>(state.iterations() * 1000),
                                                    benchmark::Counter::kIsRate);
  for (const char* suffix : {"", "-wal"})
    std::filesystem::remove(file.string() + suffix);
}
BENCHMARK(BM_StoreCommit)->Unit(benchmark::kMillisecond)->Iterations(200)->UseRealTime();

}  // namespace
