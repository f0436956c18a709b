// The `dynamics:` section of a job: the modal table, measured FRF files and
// their fit, and the library of modes measured at postures (001 Eq 16-18).

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "job_parser_dynamics.hpp"
#include "quantity_fields.hpp"
#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::job::detail {

namespace {

/// `shape: [{at: 3 mm, value: 3.232}, …]` — 000 Table 2's mass-normalized
/// shape (1/√kg) at points measured from the tool tip.
dynamics::AxialShape read_axial_shape(SectionReader& mode) {
  auto points = mode.sections("shape");
  if (points->empty())
    mode.fail("shape", "must list at least one point {at, value}");
  std::vector<double> distance_m, value;
  for (SectionReader& point : *points) {
    point.allow_schema("dynamics.modes[].shape[]");
    const double at = point.quantity("at", length_mm(kNonNegative));
    if (!distance_m.empty() && !(at > distance_m.back()))
      point.fail("at", "points must be listed from the tip outward (increasing distance)");
    distance_m.push_back(at);
    value.push_back(point.quantity("value", dimensionless()));
    point.finish();
  }
  return dynamics::AxialShape(std::move(distance_m), std::move(value));
}

ModeSpec read_mode(SectionReader& m) {
  m.allow_schema("dynamics.modes[]");
  ModeSpec mode;
  if (m.is_list("direction")) {
    const auto components = m.texts("direction");
    // A general direction [dx, dy, dz], normalized: a mode that moves the tip
    // obliquely couples the directions (cross FRFs H_xy ≠ 0).
    if (components->size() != 3)
      m.fail("direction", "a direction vector needs three components [dx, dy, dz]");
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      const auto& item = (*components)[static_cast<std::size_t>(i)];
      try {
        std::size_t used = 0;
        v[i] = std::stod(item.text, &used);
        if (used != item.text.size() || !std::isfinite(v[i]))
          throw std::invalid_argument(item.text);
      } catch (const std::exception&) {
        throw InputError(item.path, item.line, "'" + item.text + "' is not a finite number");
      }
    }
    if (!(v.norm() > 0.0))
      m.fail("direction", "the direction vector must not be zero");
    mode.direction = 'v';
    mode.direction_vector = v.normalized();
  } else {
    mode.direction = m.choice("direction", {"x", "y", "z"})[0];
    mode.direction_vector = Eigen::Vector3d::Unit(mode.direction - 'x');
  }
  mode.natural_frequency_hz = m.quantity("fn", field(dimensions::frequency, 1.0, "Hz", kPositive));
  mode.damping_ratio = m.quantity("zeta", dimensionless(kPositive, Bound{1.0, false}));
  const auto k = m.optional_quantity("k", field(dimensions::stiffness, 1.0, "N/m", kPositive));
  const auto mass = m.optional_quantity("m", field(dimensions::mass, 1.0, "kg", kPositive));
  const int given = (k ? 1 : 0) + (mass ? 1 : 0) + (m.has("shape") ? 1 : 0);
  if (given > 1) {
    const char* second = m.has("shape") ? "shape" : m.line_of("m") >= m.line_of("k") ? "m" : "k";
    m.fail(second,
           "give one of k (modal stiffness), m (modal mass) or shape (mass-normalized shape "
           "along the tool), not several");
  }
  if (given == 0) {
    m.fail("k",
           "required field missing (modal stiffness in N/m, or give the modal mass m in kg, or "
           "the mass-normalized shape along the tool)");
  }
  // k = m ωn² for a single-degree-of-freedom mode; a mass-normalized shape φ
  // at the tip gives m = 1/φ².
  const double omega = 2.0 * kPi * mode.natural_frequency_hz;
  std::string source = k ? "k" : mass ? "m" : "shape";
  if (k) {
    mode.stiffness_n_per_m = *k;
    mode.mass_kg = *k / (omega * omega);
  } else if (mass) {
    mode.mass_kg = *mass;
    mode.stiffness_n_per_m = *mass * omega * omega;
  } else {
    try {
      mode.shape = read_axial_shape(m);
    } catch (const std::invalid_argument& e) {
      m.fail("shape", e.what());
    }
    const double tip = mode.shape.at(0.0);
    if (!(std::abs(tip) > 0.0)) {
      m.fail("shape", fmt::format("extrapolates to {:g} 1/sqrt(kg) at the tool tip; a mode needs "
                                  "a non-zero shape there",
                                  tip));
    }
    mode.mass_kg = 1.0 / (tip * tip);
    mode.stiffness_n_per_m = mode.mass_kg * omega * omega;
  }
  if (!std::isfinite(mode.stiffness_n_per_m) || !std::isfinite(mode.mass_kg) ||
      !(mode.stiffness_n_per_m > 0.0) || !(mode.mass_kg > 0.0)) {
    m.fail(source, "gives a modal mass or stiffness out of range with fn = " +
                       fmt::format("{:g} Hz", mode.natural_frequency_hz));
  }
  m.finish();
  return mode;
}

std::optional<int> read_axis(SectionReader& r, std::string_view key) {
  if (!r.has(key))
    return std::nullopt;
  return r.choice(key, {"x", "y", "z"})[0] - 'x';
}

std::filesystem::path job_relative(const std::filesystem::path& source, const std::string& file) {
  return source.empty() ? std::filesystem::path(file)
                        : source.parent_path() / std::filesystem::path(file);
}

/// Format from the extension: .csv is CSV, anything else UFF58 (.uff, .unv).
FrfFileSpec::Format guessed_format(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".csv" ? FrfFileSpec::Format::csv : FrfFileSpec::Format::uff58;
}

FrfFileSpec read_frf_file(SectionReader& f, const std::filesystem::path& source,
                          std::optional<int> direction = std::nullopt) {
  f.allow_schema("dynamics.frf[]");
  FrfFileSpec spec;
  spec.path = f.path();
  spec.line = f.line();
  const auto file = f.optional_text("file");
  if (!file || file->empty())
    f.fail("file", "required field missing (path of a UFF58 or CSV file, relative to the job)");
  spec.file = job_relative(source, *file);
  const std::string guessed =
      guessed_format(spec.file) == FrfFileSpec::Format::csv ? "csv" : "uff58";
  spec.format = f.choice("format", {"uff58", "csv"}, guessed) == "csv" ? FrfFileSpec::Format::csv
                                                                       : FrfFileSpec::Format::uff58;
  spec.response_axis = read_axis(f, "response");
  spec.reference_axis = read_axis(f, "reference");
  if (direction) {
    // `frf: {x: {...}}`: the key is the measured direction (a driving point
    // unless `reference` says otherwise).
    if (spec.response_axis && *spec.response_axis != *direction)
      f.fail("response", "contradicts the direction this entry is listed under");
    spec.response_axis = direction;
    if (!spec.reference_axis)
      spec.reference_axis = direction;
  }
  if (const auto units = f.optional_text("units")) {
    Quantity unit;
    try {
      unit = parse_unit(*units);
    } catch (const std::invalid_argument& e) {
      f.fail("units", e.what());
    }
    if (unit.dimension == dimensions::receptance)
      spec.kind = dynamics::FrfKind::receptance;
    else if (unit.dimension == dimensions::mobility)
      spec.kind = dynamics::FrfKind::mobility;
    else if (unit.dimension == dimensions::accelerance)
      spec.kind = dynamics::FrfKind::accelerance;
    else
      f.fail("units", "'" + *units +
                          "' is not an FRF unit; expected a receptance (m/N, mm/N, um/N), a "
                          "mobility (m/s/N) or an accelerance (m/s^2/N)");
    spec.scale_to_si = unit.value_si;
  }
  if (spec.format == FrfFileSpec::Format::csv) {
    if (!spec.kind)
      f.fail("units", "required for CSV files (e.g. units: mm/N); it sets the FRF kind and scale");
    if (!spec.response_axis)
      f.fail("response", "required for CSV files: the measured direction, x, y or z");
    if (!spec.reference_axis)
      spec.reference_axis = spec.response_axis;  // a driving-point FRF
  }
  f.finish();
  return spec;
}

}  // namespace

std::vector<FrfFileSpec> read_frf_files(SectionReader& r, const std::filesystem::path& source) {
  std::vector<FrfFileSpec> files;
  if (r.is_map("frf")) {
    // DESIGN.md's form, one file per measured direction: {x: file, y: file},
    // each a path or a map with the list form's keys.
    auto by_direction = r.section("frf");
    by_direction->allow_schema("dynamics.frf");
    for (const char* key : {"x", "y", "z"}) {
      const int axis = key[0] - 'x';
      if (by_direction->is_map(key)) {
        auto entry = by_direction->section(key);
        files.push_back(read_frf_file(*entry, source, axis));
      } else if (auto file = by_direction->optional_text(key)) {
        FrfFileSpec spec;
        spec.path = by_direction->path_of(key);
        spec.line = by_direction->line_of(key);
        spec.file = job_relative(source, *file);
        spec.format = guessed_format(spec.file);
        if (spec.format == FrfFileSpec::Format::csv) {
          by_direction->fail(key, "a CSV file needs its units: write {file: " + *file +
                                      ", units: mm/N} (or m/s/N, m/s^2/N)");
        }
        spec.response_axis = spec.reference_axis = axis;
        files.push_back(spec);
      }
    }
    by_direction->finish();
    if (files.empty())
      r.fail("frf", "must name at least one FRF file ({x: file, y: file})");
  } else if (auto list = r.sections("frf")) {
    if (list->empty())
      r.fail("frf", "must list at least one FRF file");
    for (SectionReader& f : *list)
      files.push_back(read_frf_file(f, source));
  }
  return files;
}

namespace {

FitSettings read_fit(SectionReader& fit) {
  fit.allow_schema("dynamics.fit");
  FitSettings settings;
  settings.max_order = fit.integer_or("max_order", 2, 200, 0);
  if (auto bands = fit.sections("bands")) {
    for (SectionReader& b : *bands) {
      b.allow_schema("dynamics.fit.bands[]");
      FitSettings::Band band;
      band.low_hz = b.quantity("from", field(dimensions::frequency, 1.0, "Hz", kPositive));
      band.high_hz = b.quantity("to", field(dimensions::frequency, 1.0, "Hz", kPositive));
      if (!(band.high_hz > band.low_hz)) {
        b.fail("to", fmt::format("must exceed from ({:g} Hz)", band.low_hz));
      }
      band.max_order = b.integer_or("max_order", 2, 200, 0);
      b.finish();
      settings.bands.push_back(band);
    }
  }
  fit.finish();
  return settings;
}

/// `dynamics.postures` (001 §2.2.2): a list of {posture: [deg...], modes:
/// [...]}, every posture listing the same modes (direction, k or m) in the
/// same order; `at` and `idw: {power, joint_weights}` optional. The table is
/// interpolated later (resolve_posture_library), once robot.posture is known.
void read_posture_library(SectionReader& r, Job& job) {
  for (const char* key : {"modes", "frf", "fit", "use", "from_robot"}) {
    if (r.has(key)) {
      r.fail(key, "conflicts with dynamics.postures: the modes come from the posture library");
    }
  }
  PostureLibrary library;
  const QuantityField angle = field(dimensions::angle, kDeg, "deg");
  auto entries = r.sections("postures");
  if (entries->empty())
    r.fail("postures", "must list at least one measured posture {posture: [...], modes: [...]}");
  for (std::size_t i = 0; i < entries->size(); ++i) {
    SectionReader& e = (*entries)[i];
    e.allow_schema("dynamics.postures[]");
    const auto q = e.quantities("posture", angle);
    if (!q)
      e.fail("posture", "required: the joint angles of this measurement (deg by default)");
    if (!library.postures_rad.empty() &&
        static_cast<Eigen::Index>(q->size()) != library.postures_rad.front().size()) {
      e.fail("posture", fmt::format("has {} joint angles, the first posture {}", q->size(),
                                    library.postures_rad.front().size()));
    }
    library.postures_rad.push_back(Eigen::Map<const Eigen::VectorXd>(q->data(), q->size()));
    auto modes = e.sections("modes");
    if (!modes || modes->empty())
      e.fail("modes", "required: the modes measured at this posture");
    std::vector<ModeSpec> table;
    for (SectionReader& m : *modes) {
      table.push_back(read_mode(m));
      if (table.back().direction == 'v' || !table.back().shape.empty()) {
        m.fail(table.back().direction == 'v' ? "direction" : "shape",
               "a posture library takes modes along x, y or z with k or m (what is averaged "
               "between postures must mean the same at each)");
      }
    }
    const std::vector<ModeSpec>& first = library.tables.empty() ? table : library.tables.front();
    if (table.size() != first.size()) {
      e.fail("modes", fmt::format("lists {} modes, the first posture {}: every posture lists the "
                                  "same modes in the same order",
                                  table.size(), first.size()));
    }
    for (std::size_t k = 0; k < table.size(); ++k) {
      if (table[k].direction != first[k].direction) {
        e.fail("modes", fmt::format("mode {} is along {}, the first posture's along {}: every "
                                    "posture lists the same modes in the same order",
                                    k + 1, table[k].direction, first[k].direction));
      }
    }
    library.tables.push_back(std::move(table));
    e.finish();
  }
  if (auto at = r.quantities("at", angle, library.postures_rad.front().size())) {
    library.query_rad = Eigen::Map<const Eigen::VectorXd>(at->data(), at->size());
    library.query_source = "dynamics.at";
  }
  if (auto idw = r.section("idw")) {
    idw->allow_schema("dynamics.idw");
    library.idw.power = idw->quantity_or("power", dimensionless(kPositive), 1.0);
    if (auto w = idw->quantities("joint_weights", dimensionless(kNonNegative),
                                 library.postures_rad.front().size())) {
      library.idw.joint_weights = Eigen::Map<const Eigen::VectorXd>(w->data(), w->size());
      if (!(library.idw.joint_weights.maxCoeff() > 0.0))
        idw->fail("joint_weights", "must not all be zero");
    }
    idw->finish();
  }
  job.posture_library = std::move(library);
  job.dynamics_source = Job::DynamicsSource::postures;
  r.finish();
}

}  // namespace

/// 001 Eq 16-18 at the query posture: fn and ζ averaged, k through the
/// compliance 1/k (interpolate_modal_tables), written into job.modes.
void resolve_posture_library(Job& job) {
  if (!job.posture_library)
    return;
  PostureLibrary& library = *job.posture_library;
  const auto dof = library.postures_rad.front().size();
  if (job.robot && static_cast<Eigen::Index>(job.robot->description.joints.size()) != dof) {
    throw InputError("dynamics.postures[0].posture", 0,
                     fmt::format("has {} joint angles but the robot has {} joints", dof,
                                 job.robot->description.joints.size()));
  }
  if (library.query_source.empty()) {
    if (!job.robot || job.robot->posture_rad.empty()) {
      throw InputError("dynamics.at", 0,
                       "required with dynamics.postures (or robot.posture): the posture to "
                       "interpolate the measured modes at");
    }
    library.query_rad = Eigen::Map<const Eigen::VectorXd>(job.robot->posture_rad.data(),
                                                          job.robot->posture_rad.size());
    library.query_source = "robot.posture";
  }
  std::vector<std::vector<robot::DirectionalModeParameters>> tables;
  for (const auto& table : library.tables) {
    std::vector<robot::DirectionalModeParameters> t;
    for (const ModeSpec& m : table) {
      t.push_back(
          {m.direction - 'x', m.natural_frequency_hz, m.damping_ratio, m.stiffness_n_per_m});
    }
    tables.push_back(std::move(t));
  }
  try {
    const robot::IdwResult weights =
        robot::idw_weights(library.postures_rad, library.query_rad, library.idw);
    library.weights = weights.weights;
    library.exact_index = weights.exact_index;
    const auto modes = robot::interpolate_modal_tables(library.postures_rad, tables,
                                                       library.query_rad, library.idw);
    job.modes.clear();
    for (const auto& m : modes) {
      ModeSpec spec;
      spec.direction = static_cast<char>('x' + m.axis);
      spec.direction_vector = Eigen::Vector3d::Unit(m.axis);
      spec.natural_frequency_hz = m.natural_frequency_hz;
      spec.damping_ratio = m.damping_ratio;
      spec.stiffness_n_per_m = m.stiffness_n_per_m;
      const double omega = 2.0 * kPi * m.natural_frequency_hz;
      spec.mass_kg = m.stiffness_n_per_m / (omega * omega);
      job.modes.push_back(spec);
    }
  } catch (const std::invalid_argument& error) {
    throw InputError("dynamics.postures", 0, error.what());
  }
}

void read_dynamics(SectionReader& root, Job& job) {
  auto section = root.section("dynamics");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("dynamics");
  if (r.has("postures")) {
    read_posture_library(r, job);
    return;
  }
  for (const char* key : {"at", "idw"}) {
    if (r.has(key))
      r.fail(key, "applies to dynamics.postures (modal tables measured at several postures)");
  }
  if (auto items = r.sections("modes")) {
    if (items->empty())
      r.fail("modes", "must list at least one mode");
    for (SectionReader& m : *items)
      job.modes.push_back(read_mode(m));
  }
  job.frf_files = read_frf_files(r, job.source);
  if (auto fit = r.section("fit"))
    job.fit = read_fit(*fit);
  if (r.boolean_or("from_robot", false)) {
    // The robot model at its posture (robot.posture) gives the modes.
    if (r.has("use"))
      r.fail("use", "conflicts with from_robot: true; give one of them");
    job.dynamics_source = Job::DynamicsSource::robot;
    r.finish();
    return;
  }
  const std::string fallback = job.modes.empty() && !job.frf_files.empty() ? "fit" : "table";
  const std::string use = r.choice("use", {"table", "fit", "frf"}, fallback);
  job.dynamics_source = use == "fit"   ? Job::DynamicsSource::fit
                        : use == "frf" ? Job::DynamicsSource::frf
                                       : Job::DynamicsSource::table;
  if (use == "table" && job.modes.empty())
    r.fail("use", "is 'table' but dynamics.modes is missing");
  if (use != "table" && job.frf_files.empty())
    r.fail("use", "is '" + use + "' but dynamics.frf lists no measured FRF file");
  r.finish();
}

}  // namespace robomill::job::detail
