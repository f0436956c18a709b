// The `simulation:` section of a job (docs/job-reference.md, "simulation";
// docs/simulation.md): the structure (modal model, 002's 1/2-DOF fixations of
// Eq 32-33, the reduced 6-D robot model of Eq 23, or rigid), the run length
// and step, the part's border and the metrics' steady window. Units are
// converted here, once: lengths in mm, time in s, angles in deg, masses in
// kg, stiffness in N/m and damping in N·s/m unless written.

#include "job_parser_simulation.hpp"
#include "quantity_fields.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

namespace robomill::job::detail {
namespace {

constexpr Dimension kDampingDimension{0, 1, -1, 0};  // N·s/m = kg/s

/// `mass: 100` (1-DOF), `[100, 100]` (diagonal) or `[100, 0, 0, 100]`
/// (row-major n×n): 002 Eq 32-33's M, K, C.
Eigen::MatrixXd read_matrix(SectionReader& r, std::string_view key, const QuantityField& field,
                            int n) {
  std::vector<double> values;
  if (r.is_list(key)) {
    values = *r.quantities(key, field);
  } else {
    values = {r.quantity(key, field)};
  }
  const auto size = static_cast<std::size_t>(n);
  Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(n, n);
  if (values.size() == size) {
    for (int i = 0; i < n; ++i)
      matrix(i, i) = values[std::size_t(i)];
  } else if (values.size() == size * size && n > 1) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        matrix(i, j) = values[std::size_t(i * n + j)];
  } else {
    r.fail(key, fmt::format("expected {} values (the diagonal){} for a {}-DOF fixation, got {}", n,
                            n > 1 ? fmt::format(" or {} (the matrix row by row)", n * n) : "", n,
                            values.size()));
  }
  return matrix;
}

void read_fixation(SectionReader& r, SimulationSettings& s, int n) {
  r.allow_schema("simulation.fixation");
  s.mass_kg = read_matrix(r, "mass", field(dimensions::mass, 1.0, "kg", kNonNegative), n);
  s.stiffness_n_per_m = read_matrix(r, "stiffness", field(dimensions::stiffness, 1.0, "N/m"), n);
  const bool ratio = r.has("damping_ratio"), matrix = r.has("damping");
  if (ratio == matrix)
    r.fail(matrix ? "damping_ratio" : "damping",
           ratio ? "give either damping (N*s/m) or damping_ratio, not both"
                 : "required: damping (N*s/m, 002's C) or damping_ratio (zeta, C_ii = 2 zeta "
                   "sqrt(K_ii M_ii))");
  if (matrix) {
    s.damping_n_s_per_m = read_matrix(r, "damping", field(kDampingDimension, 1.0, "N*s/m"), n);
  } else {
    const double zeta = r.quantity(
        "damping_ratio", field(dimensions::none, 1.0, "", kNonNegative, Bound{1.0, false}));
    // 002 §3.3-3.4: C_ii = 2 ζ √(K_ii M_ii).
    s.damping_n_s_per_m = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i)
      s.damping_n_s_per_m(i, i) =
          2.0 * zeta * std::sqrt(std::max(0.0, s.stiffness_n_per_m(i, i) * s.mass_kg(i, i)));
  }
  r.finish();
  // M and K symmetric positive definite, C symmetric positive semi-definite.
  auto check = [&](const Eigen::MatrixXd& m, const char* key, bool semi) {
    if ((m - m.transpose()).cwiseAbs().maxCoeff() > 1e-9 * m.cwiseAbs().maxCoeff())
      r.fail(key, "must be symmetric");
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(m, Eigen::EigenvaluesOnly);
    const double smallest = eigen.eigenvalues().minCoeff();
    if (semi ? smallest < -1e-12 * eigen.eigenvalues().cwiseAbs().maxCoeff() : !(smallest > 0.0))
      r.fail(key, fmt::format("must be positive {}definite (smallest eigenvalue {:.4g})",
                              semi ? "semi-" : "", smallest));
  };
  check(s.mass_kg, "mass", false);
  check(s.stiffness_n_per_m, "stiffness", false);
  check(s.damping_n_s_per_m, matrix ? "damping" : "damping_ratio", true);
}

}  // namespace

void read_simulation(SectionReader& root, Job& job) {
  auto section = root.section("simulation");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("simulation");
  SimulationSettings s;
  s.line = r.line();
  s.model_name =
      r.choice("model", {"modes", "rigid", "1dof", "2dof", "3dof", "reduced6d"}, "modes");
  const int fixation_dof = s.model_name == "1dof"   ? 1
                           : s.model_name == "2dof" ? 2
                           : s.model_name == "3dof" ? 3
                                                    : 0;
  s.model = fixation_dof > 0              ? SimulationSettings::Model::fixation
            : s.model_name == "rigid"     ? SimulationSettings::Model::rigid
            : s.model_name == "reduced6d" ? SimulationSettings::Model::reduced6d
                                          : SimulationSettings::Model::modes;
  if (!job.tool || !job.cutting || !job.process)
    r.fail_here("a simulation needs the tool:, cutting: and process: sections");
  const double revolution_s = 2.0 * kPi / job.process->spindle_rad_s;

  // Run length: `duration` or `revolutions`, not both.
  const bool by_time = r.has("duration"), by_revolutions = r.has("revolutions");
  if (by_time && by_revolutions)
    r.fail("revolutions", "give either duration or revolutions, not both");
  if (!by_time && !by_revolutions)
    r.fail_here("required: duration (s) or revolutions (spindle revolutions to simulate)");
  if (by_time) {
    s.duration_line = r.line_of("duration");
    s.duration_s =
        r.quantity("duration", field(dimensions::time, 1.0, "s", kPositive, Bound{3600.0, true}));
  } else {
    s.duration_line = r.line_of("revolutions");
    s.duration_key = "revolutions";
    s.duration_s = r.integer("revolutions", 1, 10'000'000) * revolution_s;
  }
  s.steps_line = r.line_of("steps_per_tooth");
  s.steps_per_tooth_given = r.has("steps_per_tooth");
  s.steps_per_tooth = r.integer_or("steps_per_tooth", 1, 100000, s.steps_per_tooth);
  s.axial_elements = r.integer_or("axial_elements", 1, 2000, 0);
  s.record_every = r.integer_or("record_every", 1, 1'000'000, 1);
  s.start_angle_rad =
      r.quantity_or("start_angle", field(dimensions::angle, kPi / 180.0, "deg"), 0.0);
  // Memory guard: about 100 bytes per recorded step.
  const double tooth_period_s = revolution_s / job.tool->teeth;
  const double steps = s.duration_s / tooth_period_s * s.steps_per_tooth;
  if (steps / s.record_every > 2e7)
    r.fail(by_time ? "duration" : "revolutions",
           fmt::format("records {:.3g} steps (limit 2e7 rows); raise record_every to {} or shorten "
                       "the run",
                       steps / s.record_every, static_cast<long long>(std::ceil(steps / 2e7))));
  if (steps > 2e8)
    r.fail("steps_per_tooth", fmt::format("{:.3g} steps exceed the limit of 2e8", steps));

  if (auto fixation = r.section("fixation")) {
    if (fixation_dof == 0)
      r.fail("fixation",
             fmt::format("only for model 1dof, 2dof or 3dof (model is '{}')", s.model_name));
    read_fixation(*fixation, s, fixation_dof);
  } else if (fixation_dof > 0) {
    r.fail("fixation", fmt::format("required for model {}: {{mass, stiffness, damping | "
                                   "damping_ratio}} (002 Eq {})",
                                   s.model_name, fixation_dof == 1 ? "32" : "33"));
  }
  if (s.model == SimulationSettings::Model::modes && job.modes.empty() && job.frf_files.empty() &&
      job.dynamics_source == Job::DynamicsSource::table)
    r.fail("model",
           "is 'modes' (the default) but the job has no dynamics: section; add one, or "
           "use model: rigid, 1dof, 2dof, 3dof or reduced6d");
  if (s.model == SimulationSettings::Model::reduced6d && !job.robot)
    r.fail("model", "reduced6d needs a robot: section with a posture");
  s.damping_ratio = r.quantity_or(
      "damping_ratio", field(dimensions::none, 1.0, "", kPositive, Bound{1.0, false}), 0.0);

  // DESIGN.md §3 names the part `workpiece_mesh` (002 §3.3's mesh, here a
  // swept-surface memory): both names are accepted, one at a time.
  if (r.has("workpiece_mesh")) {
    if (r.has("workpiece"))
      r.fail("workpiece_mesh",
             "give the part once: workpiece and workpiece_mesh are the same section");
    s.workpiece_key = "workpiece_mesh";
  }
  if (auto workpiece = r.section(s.workpiece_key)) {
    // Literals: allow_schema keeps a view of the section's name.
    workpiece->allow_schema(s.workpiece_key == "workpiece" ? "simulation.workpiece"
                                                           : "simulation.workpiece_mesh");
    s.border_line = workpiece->line_of("border");
    s.border_gap_m =
        workpiece->quantity("border", field(dimensions::length, 1e-3, "mm", kNonNegative));
    workpiece->finish();
  }

  const int steady_revolutions =
      r.integer_or("steady_revolutions", 1, 10'000'000,
                   std::max(1, static_cast<int>(std::floor(0.2 * s.duration_s / revolution_s))));
  s.steady_window_s = steady_revolutions * revolution_s;
  if (s.steady_window_s > s.duration_s * (1.0 + 1e-9))
    r.fail(
        r.has("steady_revolutions") ? "steady_revolutions" : (by_time ? "duration" : "revolutions"),
        fmt::format("the steady window ({} revolutions, {:.4g} s) is longer than the run "
                    "({:.4g} s); the run must last at least {:.4g} s",
                    steady_revolutions, s.steady_window_s, s.duration_s, s.steady_window_s));

  if (auto damping = r.section("process_damping")) {
    damping->allow_schema("simulation.process_damping");
    s.process_damping = true;
    s.indentation_n_per_m3 =
        damping->quantity("Ksp", field(dimensions::force_per_volume, 1.0, "N/m^3", kPositive));
    s.wear_land_m =
        damping->quantity("wear_land", field(dimensions::length, 1e-6, "um", kPositive));
    s.friction = damping->quantity_or("mu", field(dimensions::none, 1.0, "", kNonNegative), 0.0);
    damping->finish();
  }
  r.finish();
  job.simulation = std::move(s);
}

}  // namespace robomill::job::detail
