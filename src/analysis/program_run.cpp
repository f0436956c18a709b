// `robomill toolpath` of a job (analysis/program_run.hpp): the program read,
// run over the stock, the robot along it, and on request improved.

#include "robomill/analysis/program_run.hpp"
#include "robomill/analysis/program_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "robomill/core/error.hpp"
#include "robomill/io/csv.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/robot/kinematics.hpp"

namespace robomill::analysis {

// The stock the job describes: a full box, or the height map an earlier run
// left (stock.csv: x_mm, y_mm, z_mm with x fastest).
toolpath::DexelStock job_stock(const job::Job& job) {
  const job::StockSettings& s = *job.stock;
  const toolpath::StockBox box{s.min_m, s.max_m};
  try {
    if (s.height_map.empty())
      return toolpath::DexelStock(box, s.resolution_m);
    const io::CsvTable map = io::read_csv(s.height_map);
    const int x = map.find("x_mm"), y = map.find("y_mm"), z = map.find("z_mm");
    if (x < 0 || y < 0 || z < 0 || map.rows() < 1)
      throw InputError("stock.height_map", s.line,
                       fmt::format("'{}' needs the columns x_mm, y_mm, z_mm (stock.csv of "
                                   "robomill toolpath)",
                                   s.height_map.string()));
    std::size_t nx = 1;
    while (nx < map.rows() && map.at(nx, y) == map.at(0, y))
      ++nx;
    if (map.rows() % nx != 0)
      throw InputError(
          "stock.height_map", s.line,
          fmt::format("'{}' is not a regular grid (x fastest, then y)", s.height_map.string()));
    std::vector<double> heights(map.rows());
    for (std::size_t r = 0; r < map.rows(); ++r)
      heights[r] = map.at(r, z) * 1e-3;
    return toolpath::DexelStock::from_height_map(box, s.resolution_m, static_cast<int>(nx),
                                                 static_cast<int>(map.rows() / nx), heights);
  } catch (const std::invalid_argument& error) {
    throw InputError("stock", s.line, error.what());
  }
}

namespace {

// A program length that matches the job's only in the other unit: the
// program was read in the wrong one, and the error says what fixes it — for
// a CL file without a UNITS record (an NX CLSF) toolpath.units, else the
// program's own unit word. Empty when it matches in neither unit.
std::string other_unit_hint(double program_m, double job_m, const toolpath::Program& program) {
  constexpr double kMmPerInch = 25.4;
  const auto same = [](double a, double b) { return std::abs(a - b) <= 1e-6 + 1e-6 * b; };
  // The APT reader notes "no UNITS record: ..." exactly when the file has none.
  bool undeclared = false;
  for (const toolpath::ProgramNote& note : program.notes)
    undeclared =
        undeclared || (program.dialect == "apt" && note.text.starts_with("no UNITS record"));
  const auto fix = [&](const char* unit) {
    return undeclared ? fmt::format("say so with toolpath.units: {}", unit)
                      : std::string("check the program's unit word (UNITS, G20/G21)");
  };
  if (job_m > 0.0 && same(program_m * kMmPerInch, job_m))
    return fmt::format(
        " (read in inches it is {:.4g} mm, the job's: if the program is in inches, {})",
        program_m * kMmPerInch * 1e3, fix("inch"));
  if (job_m > 0.0 && same(program_m / kMmPerInch, job_m))
    return fmt::format(
        " (read in millimetres it is {:.4g} mm, the job's: if the program is in millimetres, {})",
        program_m / kMmPerInch * 1e3, fix("mm"));
  return {};
}

}  // namespace

toolpath::Tooling job_tooling(const job::Job& job, const toolpath::Program& program) {
  toolpath::Tooling tooling;
  const job::ToolpathSettings& settings = *job.toolpath;
  if (settings.tools.empty())
    tooling.emplace(0, tool::Tool(*job.tool));
  for (const auto& [number, spec] : settings.tools)
    tooling.emplace(number, tool::Tool(spec));
  for (const toolpath::ToolCall& call : program.tool_calls) {
    auto it = tooling.find(call.tool);
    if (it == tooling.end())
      it = tooling.find(0);
    if (it == tooling.end())
      continue;
    const tool::Tool& cutter = it->second;
    const std::string where = settings.tools.empty() ? std::string("the job's tool")
                                                     : fmt::format("toolpath.tools.T{}", call.tool);
    if (call.diameter_m && std::abs(*call.diameter_m - cutter.diameter_m()) > 1e-6)
      throw InputError(
          settings.file.filename().string(), call.line,
          fmt::format("the program's cutter T{} is {:.4g} mm in diameter, {} is "
                      "{:.4g} mm{}; describe the program's cutter",
                      call.tool, *call.diameter_m * 1e3, where, cutter.diameter_m() * 1e3,
                      other_unit_hint(*call.diameter_m, cutter.diameter_m(), program)));
    if (call.corner_radius_m) {
      // 0: flat, R: ball, r_c: bull nose (Tool::corner_radius_m gives each).
      const double job_corner = cutter.corner_radius_m();
      if (std::abs(*call.corner_radius_m - job_corner) > 1e-6) {
        const double r = *call.corner_radius_m;
        const double R = cutter.radius_m();
        const std::string program_kind = r <= 1e-9                 ? "a flat end mill"
                                         : std::abs(r - R) <= 1e-6 ? "a ball-end mill"
                                                                   : "a bull-nose end mill";
        throw InputError(
            settings.file.filename().string(), call.line,
            fmt::format("the program's cutter T{} has a corner radius of {:.4g} mm ({}), {} is a "
                        "{} end mill with corner radius {:.4g} mm{}; robomill models flat (0), "
                        "bull-nose (0 < r < R: tool.type: bull with tool.corner_radius) and ball "
                        "(R) ends: describe the program's cutter",
                        call.tool, r * 1e3, program_kind, where,
                        cutter.type() == tool::ToolType::ball   ? "ball"
                        : cutter.type() == tool::ToolType::bull ? "bull-nose"
                                                                : "flat",
                        job_corner * 1e3, other_unit_hint(r, job_corner, program)));
      }
    }
  }
  return tooling;
}

toolpath::ProgramAnalysisSettings program_analysis_settings(const job::ToolpathSettings& settings,
                                                            int threads, std::string source_name) {
  toolpath::ProgramAnalysisSettings analysis;
  analysis.sample_spacing_m = settings.spacing_m;
  analysis.rapid_speed_m_s = settings.rapid_speed_m_s;
  analysis.default_spindle_rad_s = settings.spindle_rad_s;
  analysis.force_steps_per_tooth = settings.force_steps_per_tooth;
  analysis.block_samples = settings.block_samples;
  analysis.threads = threads;
  analysis.source_name = std::move(source_name);
  return analysis;
}

double expected_samples(const job::Job& job, const ProgramRun& run) {
  const double spacing_m =
      job.toolpath->spacing_m > 0.0 ? job.toolpath->spacing_m : 0.5 * job.stock->resolution_m;
  double reach_m = 0.0;
  for (const auto& [number, tool] : *run.tooling)
    reach_m = std::max(reach_m, toolpath::cutter_reach_m(toolpath::cutter_shape(tool)));
  const toolpath::StockBox box{job.stock->min_m, job.stock->max_m};
  double path_length_m = 0.0;
  for (const toolpath::Move& move : run.program.moves) {
    const toolpath::MoveStretch near = toolpath::move_near_box(move, box, reach_m);
    if (!near.empty())
      path_length_m +=
          toolpath::path_length_m(move) * (std::min(1.0, near.to_u) - std::max(0.0, near.from_u));
  }
  return path_length_m / std::max(spacing_m, 1e-6) +
         2.0 * static_cast<double>(run.program.moves.size());
}

RobotDrawing robot_drawing(const robot_path::RobotAlongPath& along, const Eigen::VectorXd& q_rad) {
  return {along.joint_origins(q_rad), robot::tool_pose(along.model(), q_rad)};
}

ProgramRun run_program(const job::Job& job, const ProgramRunOptions& options) {
  job::require(job, {job::Section::cutting});
  if (!job.toolpath)
    throw InputError("toolpath", 0, "required section missing: the program (toolpath.file)");
  if (!job.stock)
    throw InputError("stock", 0, "required section missing: the stock box (stock.box: {min, max})");
  const auto start = std::chrono::steady_clock::now();
  const job::ToolpathSettings& settings = *job.toolpath;
  ProgramRun run;
  run.program = analysis::read_program(settings);
  run.tooling = std::make_unique<toolpath::Tooling>(job_tooling(job, run.program));
  toolpath::DexelStock stock = job_stock(job);
  toolpath::ProgramAnalysisSettings analysis_settings =
      program_analysis_settings(settings, options.threads, settings.file.filename().string());

  // The robot along the program, when the job puts the part in a robot cell.
  run.robot_setup = analysis::robot_path_setup(job, options.threads);
  const analysis::RobotPathSetup* setup = run.robot_setup ? &*run.robot_setup : nullptr;
  if (setup)
    run.robot = std::make_unique<robot_path::RobotAlongPath>(*setup->model, setup->structure,
                                                             *run.tooling, *job.cutting,
                                                             setup->stability, setup->settings);
  if (options.optimize && !setup)
    throw InputError("toolpath", settings.line,
                     "--optimize needs the robot on the program: a robot: section and "
                     "workpiece.pose");
  if (options.optimize && setup->stability.advice_speeds_rad_s.empty() &&
      !(job.robot_path && job.robot_path->feed_limits))
    throw InputError("stability.speeds", 0,
                     "--optimize needs the spindle range it may choose from (stability.speeds: "
                     "{from, to, count}) or the feed's caps (robot_path.feed_limits)");

  if (setup && job.uncertainty) {
    run.draws.emplace(robot_path_draws(job, options.threads));
    run.robot->set_draws(run.draws->path_draws());
  }
  if (options.on_start)
    options.on_start(run);

  // Several processes: each computes its blocks in full and every block's
  // postures; process 0 gathers the rest and alone goes on.
  const BlockSharing* sharing =
      options.sharing && options.sharing->processes > 1 ? options.sharing : nullptr;
  const bool serving = sharing && sharing->process != 0;
  // The sink's MPI calls must come from this thread (MPI_THREAD_FUNNELED).
  analysis_settings.overlap_blocks = sharing == nullptr;
  FirstRunRecord record;
  std::vector<robot_path::RobotSample> robot_block;
  std::size_t block = 0;
  robot_path::RobotAlongPath* robot = run.robot.get();
  const toolpath::SampleSink sink = [&](std::span<const toolpath::PathSample> samples) {
    if (robot) {
      robot_block.resize(samples.size());
      if (!sharing) {
        robot->evaluate(samples, robot_block);
      } else {
        robot->postures(samples, robot_block);
        robot_path::ShortcutChecks checks;
        if (block % static_cast<std::size_t>(sharing->processes) ==
            static_cast<std::size_t>(sharing->process)) {
          checks = robot->compute(samples, robot_block);
          if (serving)
            sharing->send(block, robot_block, checks);
        } else if (!serving) {
          sharing->receive(block, robot_block, checks);
        }
        if (!serving)
          robot->record(samples, robot_block, checks);
      }
    }
    ++block;
    if (serving)
      return;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const toolpath::PathSample& sample = samples[i];
      if (options.optimize && robot)
        record.add(sample, robot_block[i]);
      if (sample.engaged_rad > run.max_engagement_rad &&
          sample.kind != toolpath::MotionKind::rapid) {
        run.max_engagement_rad = sample.engaged_rad;
        run.max_engagement_line = sample.line;
      }
    }
    if (options.on_samples)
      options.on_samples(samples, robot ? std::span<const robot_path::RobotSample>(robot_block)
                                        : std::span<const robot_path::RobotSample>());
  };
  run.analysis = toolpath::analyse_program(run.program, *run.tooling, *job.cutting, stock,
                                           analysis_settings, sink, [&](double fraction) {
                                             if (options.progress)
                                               options.progress(fraction);
                                           });
  if (serving)
    return run;
  if (run.analysis.engaged_samples == 0) {
    throw InputError("toolpath.origin", settings.line,
                     fmt::format("no move of '{}' touches the stock: check toolpath.origin "
                                 "(where the program's zero sits in the workpiece frame) against "
                                 "stock.box",
                                 settings.file_text));
  }
  run.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.stock.emplace(std::move(stock));
  if (!robot)
    return run;

  const robot_path::RobotPathSummary& r = run.robot_summary.emplace(robot->finish());
  if (r.samples > 0 && r.unreachable == r.samples) {
    const Eigen::Vector3d table = job.workpiece->cell.table_origin_m * 1e3;
    throw InputError("workpiece.pose", job.robot_path ? job.robot_path->line : 0,
                     fmt::format("the robot reaches no sample of the program (from line {}) "
                                 "with the part on the table at [{:.0f}, {:.0f}, {:.0f}] mm: "
                                 "move the table or the pose within the robot's reach",
                                 r.first_unreachable_line, table.x(), table.y(), table.z()));
  }
  // A better program for a cell that cannot run this one would mislead:
  // the improvement stops here, naming where the robot falls short.
  if (options.optimize && r.unreachable > 0)
    throw InputError("workpiece.pose", job.robot_path ? job.robot_path->line : 0,
                     fmt::format("--optimize: the robot cannot reach {} samples of the program "
                                 "(the first at program line {}); no program is written: move "
                                 "the part within reach (workpiece.table, workpiece.pose) or "
                                 "run without --optimize to see every line out of reach",
                                 r.unreachable, r.first_unreachable_line));
  if (options.optimize)
    run.improvement = improve_program(job, run.program, *run.tooling, *setup, *robot, record,
                                      run.analysis, options.scratch_dir, options.threads);
  return run;
}

}  // namespace robomill::analysis
