// robomill — predicts and plans robotic milling. See DESIGN.md §4.
//
// Exit codes: 0 success, 2 invalid job or arguments, 1 any other failure.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <thread>

#include "commands.hpp"
#ifdef ROBOMILL_WITH_MPI
#include "mpi.hpp"
#endif
#include "robomill/core/error.hpp"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitInvalidInput = 2;

void add_job_options(CLI::App& command, robomill::app::JobCommandOptions& options,
                     bool writes_output) {
  command.add_option("JOB", options.job_file, "job file (YAML)")->required();
  command
      .add_option("--set", options.overrides,
                  "override a job field before validation, e.g. --set process.ae=\"2 mm\"")
      ->type_name("KEY.PATH=VALUE");
  if (writes_output) {
    command.add_option("--out", options.out_dir,
                       "output folder (default: the job's output.dir, else out/<command>)");
    command.add_option("--threads", options.threads, "worker threads (default: all cores)")
        ->check(CLI::NonNegativeNumber);
  }
  command.add_flag("--quiet", options.quiet, "print nothing but errors");
}

/// A subcommand that runs on a job file, with the shared job options.
CLI::App* add_job_command(CLI::App& app, const std::string& name, const std::string& description,
                          robomill::app::JobCommandOptions& options, bool writes_output = true) {
  CLI::App* command = app.add_subcommand(name, description);
  add_job_options(*command, options, writes_output);
  return command;
}

/// Every subcommand's options and the subcommand itself, registered by the
/// add_*_commands below in the order `robomill --help` lists them.
struct Commands {
  robomill::app::JobCommandOptions validate_options, forces_options, stability_options;
  robomill::app::JobCommandOptions fit_options;
  robomill::app::JobCommandOptions deflection_options;
  robomill::app::JobCommandOptions robot_options;
  robomill::app::JobCommandOptions optimize_options;
  robomill::app::JobCommandOptions simulate_options;
  robomill::app::JobCommandOptions surface_options;
  robomill::app::JobCommandOptions toolpath_options;
  robomill::app::JobCommandOptions listen_options;
  robomill::app::JobCommandOptions learn_options;
  robomill::app::JobCommandOptions advise_options;
  robomill::app::IdentifyOptions identify_options;
  robomill::app::IdentifyStiffnessOptions stiffness_options;
  robomill::app::FrfCommandOptions frf_options;
  robomill::app::AtlasOptions atlas_options;
  robomill::app::ReportOptions report_options;

  CLI::App* validate = nullptr;
  CLI::App* forces = nullptr;
  CLI::App* stability = nullptr;
  CLI::App* fit = nullptr;
  CLI::App* deflection_command = nullptr;
  CLI::App* robot = nullptr;
  CLI::App* optimize = nullptr;
  CLI::App* simulate = nullptr;
  CLI::App* surface_command = nullptr;
  CLI::App* toolpath_command = nullptr;
  CLI::App* listen_command = nullptr;
  CLI::App* learn_command = nullptr;
  CLI::App* advise = nullptr;
  CLI::App* identify = nullptr;
  CLI::App* identify_stiffness = nullptr;
  CLI::App* frf = nullptr;
  CLI::App* atlas_command = nullptr;
  CLI::App* report = nullptr;
};

/// validate, forces, stability, fit-modes, deflection, robot, optimize,
/// simulate and surface: commands on a job file with the shared options only.
void add_analysis_commands(CLI::App& app, Commands& c) {
  c.validate = add_job_command(app, "validate", "check a job file without running it",
                               c.validate_options, false);

  c.forces = add_job_command(
      app, "forces",
      "milling forces and spindle torque over whole revolutions → forces.csv, summary.json",
      c.forces_options);

  c.stability = add_job_command(
      app, "stability",
      "stability lobe diagram: limiting depth per spindle speed → sld.csv (map.csv), summary.json",
      c.stability_options);

  c.fit = add_job_command(
      app, "fit-modes",
      "modal parameters from the job's measured FRFs (dynamics.frf) → modes.csv, frf_fit.csv, "
      "stabilization.csv, modes.yaml, summary.json",
      c.fit_options);

  c.deflection_command = add_job_command(
      app, "deflection",
      "force-induced deformation of tool and robot and the actual contact boundary (000 §2, §4) "
      "over a sweep of axial depths → deflection.csv, summary.json",
      c.deflection_options);

  c.robot = add_job_command(
      app, "robot",
      "the robot's structure at a posture: pose, Jacobian, compliance, natural frequencies, "
      "tool-tip FRF; with robot.map a workspace map → summary.json, frf.csv, modes.csv, map.csv",
      c.robot_options);

  c.optimize = add_job_command(
      app, "optimize",
      "workpiece pose minimizing the mean tool offset along the path (004): NLopt global search "
      "+ local polish → summary.json, evaluations.csv, path.csv, landscape.csv",
      c.optimize_options);

  c.simulate = add_job_command(
      app, "simulate",
      "nonlinear regenerative time-domain simulation with material removal (002 §3): forces and "
      "tool displacement, static deviation, overshoot, settling, first frequency, chatter → "
      "timeseries.csv, spectrum.csv, summary.json",
      c.simulate_options);

  c.surface_command = add_job_command(
      app, "surface",
      "machined surface of a ball-end raster by a Z-map (001): runout, lead/tilt/redundancy, "
      "posture-dependent vibration; Ra, Rq, Sa, Sq, Sz → surface.csv, profiles.csv, surface.bmp, "
      "summary.json",
      c.surface_options);
}

/// toolpath (with --optimize), listen and advise.
void add_program_commands(CLI::App& app, Commands& c) {
  c.toolpath_command = add_job_command(
      app, "toolpath",
      "the program the cell runs (G-code, APT CL, KUKA KRL) over a tri-dexel stock: engagement, "
      "forces, torque and power at every sample → samples.csv, moves.csv, stock.csv, "
      "summary.json",
      c.toolpath_options);
  c.toolpath_command->add_flag(
      "--optimize", c.toolpath_options.optimize,
      "with a robot on the program: choose each S word's spindle speed in stability.speeds for "
      "the postures it runs at, write program_optimized.<ext> and re-run the analysis on it");

  c.listen_command = add_job_command(
      app, "listen",
      "chatter from a recorded cut (WAV/FLAC/AIFF, MATLAB, CSV, UFF58): spindle speed measured, "
      "tooth comb, mains and steady lines set aside, the chatter verdict, frequency and onset, "
      "and the spindle speeds to try → spectrum.csv, spectrogram.csv, recordings.csv, "
      "summary.json",
      c.listen_options);

  c.learn_command = add_job_command(
      app, "learn",
      "Bayesian updating of the uncertain inputs from the test cuts (experiments), the prior "
      "and posterior lobes, and the next test to run → posterior.csv, lobes_quantiles.csv, "
      "chatter_probability.csv, experiments.csv, summary.json",
      c.learn_options);

  c.advise = add_job_command(
      app, "advise",
      "cutting-parameter advice: spindle speed and depth maximizing the removal rate inside the "
      "stability diagram and under the tool-offset limit; the redundancy angle along a path → "
      "advice.json, summary.json, advice_map.csv, redundancy.csv",
      c.advise_options);
}

/// identify-cutting: cutting coefficients from a CSV of mean forces.
void add_identify_cutting_command(CLI::App& app, Commands& c) {
  robomill::app::IdentifyOptions& identify_options = c.identify_options;
  CLI::App* identify = app.add_subcommand(
      "identify-cutting",
      "least-squares linear cutting coefficients from mean forces measured at several feeds "
      "(columns feed_per_tooth_mm,fx_N,fy_N,fz_N; optional ap_mm, ae_mm)");
  c.identify = identify;
  identify->add_option("DATA", identify_options.data_file, "CSV of mean forces")->required();
  identify->add_option("--job", identify_options.job_file,
                       "take teeth, diameter, ap, ae and direction from this job");
  identify->add_option("--teeth", identify_options.teeth, "number of teeth");
  identify->add_option("--ap", identify_options.axial_depth, "axial depth (default unit mm)");
  identify->add_option("--ae", identify_options.radial_depth,
                       "radial depth (default unit mm; default: slot)");
  identify->add_option("--diameter", identify_options.diameter,
                       "tool diameter (default unit mm; needed for partial immersion)");
  identify->add_option("--direction", identify_options.direction, "down or up milling")
      ->check(CLI::IsMember({"down", "up"}));
  identify
      ->add_option("--measured-on", identify_options.measured_on,
                   "'tool' (forces on the cutter, tool frame) or 'workpiece' (a "
                   "dynamometer under the part: forces are negated)")
      ->check(CLI::IsMember({"tool", "workpiece"}));
  identify->add_option("--out", identify_options.out_dir,
                       "output folder (default out/identify-cutting)");
  identify->add_flag("--quiet", identify_options.quiet, "print nothing but errors");
}

/// identify-stiffness: joint stiffness from static loading tests.
void add_identify_stiffness_command(CLI::App& app, Commands& c) {
  robomill::app::IdentifyStiffnessOptions& stiffness_options = c.stiffness_options;
  CLI::App* identify_stiffness = app.add_subcommand(
      "identify-stiffness",
      "joint stiffness Kq by least squares from static loading tests (000 §6.1): CSV columns "
      "q1_deg..qn_deg, fx_N,fy_N,fz_N [,mx_Nm,my_Nm,mz_Nm], dx_mm,dy_mm,dz_mm "
      "[,target_x_mm,…] [,load_x_mm,…] → summary.json, fit.csv, joint_stiffness.yaml");
  c.identify_stiffness = identify_stiffness;
  identify_stiffness->add_option("DATA", stiffness_options.data_file, "CSV of loading tests")
      ->required();
  identify_stiffness
      ->add_option("--job", stiffness_options.job.job_file,
                   "job whose robot section gives the geometry (its joint_stiffness is the "
                   "value the result is compared with)")
      ->required();
  identify_stiffness->add_option("--set", stiffness_options.job.overrides,
                                 "override a job field, e.g. --set robot.tool.xyz=[0,0,300]");
  identify_stiffness->add_option("--out", stiffness_options.job.out_dir,
                                 "output folder (default: the job's output.dir, else "
                                 "out/identify-stiffness)");
  identify_stiffness
      ->add_option("--max-condition", stiffness_options.max_condition,
                   "refuse data whose scaled condition number exceeds this (default 1e6)")
      ->check(CLI::PositiveNumber);
  identify_stiffness->add_flag(
      "--synthesize", stiffness_options.synthesize,
      "instead: write loading_tests.csv with the displacements the job's robot would show for "
      "DATA's postures and loads (plan a test, or check the method)");
  identify_stiffness->add_option("--noise", stiffness_options.noise,
                                 "with --synthesize: relative displacement noise, e.g. 0.01");
  identify_stiffness->add_option("--seed", stiffness_options.seed,
                                 "with --synthesize: seed of the noise (default 1)");
  identify_stiffness->add_flag("--quiet", stiffness_options.job.quiet, "print nothing but errors");
}

/// frf: tool-tip FRFs of the job's modal table.
void add_frf_command(CLI::App& app, Commands& c) {
  robomill::app::FrfCommandOptions& frf_options = c.frf_options;
  CLI::App* frf = add_job_command(
      app, "frf",
      "tool-tip FRFs of the job's modal table (optionally with noise) → frf.uff or frf_*.csv, "
      "summary.json",
      frf_options.job);
  c.frf = frf;
  frf->add_option("--from", frf_options.from, "lowest frequency (default 0 Hz)");
  frf->add_option("--to", frf_options.to, "highest frequency (default 1.5 x the highest mode)");
  frf->add_option("--step", frf_options.step,
                  "frequency step (default: a tenth of the narrowest half-power band)");
  frf->add_option("--spacing", frf_options.spacing, "linear (default) or log");
  frf->add_option("--points", frf_options.points, "frequencies of a log grid (default 5000)");
  frf->add_option("--kind", frf_options.kind, "receptance (default), mobility or accelerance");
  frf->add_option("--format", frf_options.format, "uff58 (ASCII, default), uff58b (binary) or csv");
  frf->add_option("--noise", frf_options.noise_relative,
                  "relative complex noise, e.g. 0.02 for 2 % of |H| (default 0)");
  frf->add_option("--seed", frf_options.seed, "seed of the noise (default 1)");
}

/// atlas (its store, --export, --restart) and report.
void add_atlas_and_report_commands(CLI::App& app, Commands& c) {
  robomill::app::AtlasOptions& atlas_options = c.atlas_options;
  CLI::App* atlas_command = add_job_command(
      app, "atlas",
      "workspace atlas (issue 11): grid points x redundancy angles, per item compliance, lowest "
      "natural frequency, min/max stable depth; thread-parallel, resumable SQLite store "
      "(atlas.store); --export OUT writes atlas.csv, summary.json",
      atlas_options.job, false);
  c.atlas_command = atlas_command;
  atlas_command
      ->add_option("--threads", atlas_options.job.threads, "worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  atlas_command->add_option("--export", atlas_options.export_dir,
                            "write atlas.csv and summary.json from the store into this folder "
                            "(computes nothing)");
  atlas_command->add_flag("--restart", atlas_options.restart,
                          "discard a store written by another job or version and start over");

  robomill::app::ReportOptions& report_options = c.report_options;
  CLI::App* report = app.add_subcommand(
      "report", "rebuild report.html from a command's output folder (its summary.json and files)");
  c.report = report;
  report->add_option("OUTDIR", report_options.dir, "a command's output folder")->required();
  report->add_flag("--quiet", report_options.quiet, "print nothing but errors");
}

/// Runs the parsed subcommand; throws what it throws (run() reports it).
int run_parsed(const Commands& c, [[maybe_unused]] int rank, int ranks) {
  if (c.atlas_command->parsed() && c.atlas_options.export_dir.empty() && ranks > 1) {
#ifdef ROBOMILL_WITH_MPI
    return robomill::app::run_atlas_mpi(c.atlas_options, rank, ranks);
#endif
  }
  if (c.toolpath_command->parsed() && ranks > 1) {
#ifdef ROBOMILL_WITH_MPI
    return robomill::app::run_toolpath_mpi(c.toolpath_options, rank, ranks);
#endif
  }
  if (ranks > 1) {
    throw robomill::InputError("mpirun", 0,
                               "only `robomill atlas JOB` and `robomill toolpath JOB` run over "
                               "MPI ranks; start this command without mpirun");
  }
  if (c.validate->parsed())
    return robomill::app::run_validate(c.validate_options);
  if (c.forces->parsed())
    return robomill::app::run_forces(c.forces_options);
  if (c.stability->parsed())
    return robomill::app::run_stability(c.stability_options);
  if (c.identify->parsed())
    return robomill::app::run_identify_cutting(c.identify_options);
  if (c.deflection_command->parsed())
    return robomill::app::run_deflection(c.deflection_options);
  if (c.robot->parsed())
    return robomill::app::run_robot(c.robot_options);
  if (c.fit->parsed())
    return robomill::app::run_fit_modes(c.fit_options);
  if (c.optimize->parsed())
    return robomill::app::run_optimize(c.optimize_options);
  if (c.simulate->parsed())
    return robomill::app::run_simulate(c.simulate_options);
  if (c.advise->parsed())
    return robomill::app::run_advise(c.advise_options);
  if (c.surface_command->parsed())
    return robomill::app::run_surface(c.surface_options);
  if (c.toolpath_command->parsed())
    return robomill::app::run_toolpath(c.toolpath_options);
  if (c.listen_command->parsed())
    return robomill::app::run_listen(c.listen_options);
  if (c.learn_command->parsed())
    return robomill::app::run_learn(c.learn_options);
  if (c.identify_stiffness->parsed())
    return robomill::app::run_identify_stiffness(c.stiffness_options);
  if (c.frf->parsed())
    return robomill::app::run_frf(c.frf_options);
  if (c.atlas_command->parsed())
    return robomill::app::run_atlas(c.atlas_options);
  if (c.report->parsed())
    return robomill::app::run_report(c.report_options);
  return kExitFailure;
}

/// The command line, run by every MPI rank when started by mpirun (only the
/// atlas uses the ranks; rank 0 alone reports invalid input).
int run(int argc, char** argv, int rank, int ranks) {
  CLI::App app{"robomill — predicts and plans robotic milling"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "robomill 0.1.0");

  Commands commands;
  add_analysis_commands(app, commands);
  add_program_commands(app, commands);
  add_identify_cutting_command(app, commands);
  add_identify_stiffness_command(app, commands);
  add_frf_command(app, commands);
  add_atlas_and_report_commands(app, commands);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitInvalidInput;
  }

  try {
    return run_parsed(commands, rank, ranks);
  } catch (const robomill::InputError& error) {
    // Under mpirun every rank reads the job: rank 0 says what is wrong. A
    // failing rank aborts them all (MpiSession::exit), so another rank
    // waits a moment first, and speaks only if rank 0 did not (an error of
    // its own).
    if (rank != 0)
      std::this_thread::sleep_for(std::chrono::seconds(2));
    std::cerr << "robomill: error: " << error.what()
              << (rank != 0 ? " (MPI rank " + std::to_string(rank) + ")" : std::string()) << '\n';
    return kExitInvalidInput;
  } catch (const std::invalid_argument& error) {
    // Model constructors reject what the parser let through (it should not).
    std::cerr << "robomill: invalid input: " << error.what() << '\n';
    return kExitInvalidInput;
  } catch (const std::exception& error) {
    std::cerr << "robomill: failed: " << error.what() << '\n';
    return kExitFailure;
  }
  return kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
#ifdef ROBOMILL_WITH_MPI
  robomill::app::MpiSession mpi(argc, argv);
  return mpi.exit(run(argc, argv, mpi.rank(), mpi.ranks()));
#else
  return run(argc, argv, 0, 1);
#endif
}
