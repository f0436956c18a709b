#include "robomill/report/key_inputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <type_traits>
#include <variant>

namespace robomill::report {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
constexpr double kRpm = 60.0 / (2.0 * std::numbers::pi);

std::string num(double value) {
  return std::isfinite(value) ? fmt::format("{:.4g}", value) : std::string("—");
}

std::string with_unit(double value, const char* unit) {
  return num(value) + " " + unit;
}

std::string list(const std::vector<double>& values, double scale, const char* unit) {
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i)
    text += (i ? ", " : "") + num(values[i] * scale);
  return text + "] " + unit;
}

class Rows {
 public:
  void add(const std::string& group, const std::string& name, const std::string& value) {
    rows_.push_back({{"group", group}, {"name", name}, {"value", value}});
  }
  nlohmann::json take() { return std::move(rows_); }

 private:
  nlohmann::json rows_ = nlohmann::json::array();
};

void add_cutting(Rows& rows, const cutting::CuttingLaw& law) {
  rows.add("cutting", "law", std::string(cutting::law_name(law)));
  std::visit(
      [&](const auto& l) {
        using Law = std::decay_t<decltype(l)>;
        if constexpr (std::is_same_v<Law, cutting::LinearLaw>) {
          rows.add("cutting", "Ktc, Krc, Kac",
                   fmt::format("{}, {}, {} N/mm²", num(l.Ktc_pa * 1e-6), num(l.Krc_pa * 1e-6),
                               num(l.Kac_pa * 1e-6)));
          rows.add("cutting", "Kte, Kre, Kae",
                   fmt::format("{}, {}, {} N/mm", num(l.Kte_n_per_m * 1e-3),
                               num(l.Kre_n_per_m * 1e-3), num(l.Kae_n_per_m * 1e-3)));
        } else if constexpr (std::is_same_v<Law, cutting::ExponentialLaw>) {
          rows.add("cutting", "kF", with_unit(l.kF_n_per_m * 1e-3, "N/mm"));
          rows.add("cutting", "exponent m", num(l.exponent));
          rows.add("cutting", "h_ref", with_unit(l.reference_chip_m * 1e3, "mm"));
          rows.add("cutting", "kr, ka", num(l.radial_ratio) + ", " + num(l.axial_ratio));
        } else if constexpr (std::is_same_v<Law, cutting::FractionalLaw>) {
          rows.add("cutting", "k0", with_unit(l.k0_n_per_m * 1e-3, "N/mm"));
          rows.add("cutting", "hs", with_unit(l.hs_m * 1e3, "mm"));
          rows.add("cutting", "r", num(l.r));
          rows.add("cutting", "kr, ka", num(l.radial_ratio) + ", " + num(l.axial_ratio));
        } else {
          rows.add("cutting", "kc1", with_unit(l.kc1_pa * 1e-6, "N/mm²"));
          rows.add("cutting", "b1, kc2, b2", num(l.b1) + ", " + num(l.kc2) + ", " + num(l.b2));
          rows.add("cutting", "h_ref", with_unit(l.reference_chip_m * 1e3, "mm"));
        }
      },
      law);
}

const char* method_name(job::StabilitySettings::Method method) {
  switch (method) {
    case job::StabilitySettings::Method::zoa:
      return "zoa";
    case job::StabilitySettings::Method::sdm:
      return "sdm";
    case job::StabilitySettings::Method::fdm:
      return "fdm";
    case job::StabilitySettings::Method::fdm2:
      return "fdm2";
  }
  return "?";
}

// The rows of one section of the job each (key_inputs_json gives their order).
void add_tool(Rows& rows, const tool::ToolSpec& t) {
  rows.add("tool", "type", tool::type_name(t.type));
  if (t.type == tool::ToolType::bull)
    rows.add("tool", "corner_radius", with_unit(t.corner_radius_m * 1e3, "mm"));
  rows.add("tool", "diameter", with_unit(t.diameter_m * 1e3, "mm"));
  rows.add("tool", "teeth", std::to_string(t.teeth));
  rows.add("tool", "helix", with_unit(t.helix_rad * kDeg, "°"));
  if (t.overhang_m > 0.0)
    rows.add("tool", "overhang", with_unit(t.overhang_m * 1e3, "mm"));
  if (t.runout.offset_m != 0.0)
    rows.add(
        "tool", "runout",
        fmt::format("{} µm at {}°", num(t.runout.offset_m * 1e6), num(t.runout.angle_rad * kDeg)));
}

void add_process(Rows& rows, const cutting::MillingProcess& p) {
  rows.add("process", "spindle", with_unit(p.spindle_rad_s * kRpm, "rpm"));
  rows.add("process", "feed per tooth", with_unit(p.feed_per_tooth_m * 1e3, "mm"));
  rows.add("process", "ap (axial depth)", with_unit(p.axial_depth_m * 1e3, "mm"));
  rows.add("process", "ae (radial depth)", with_unit(p.radial_depth_m * 1e3, "mm"));
  rows.add("process", "direction", std::string(cutting::to_string(p.direction)));
}

void add_dynamics(Rows& rows, const job::Job& job) {
  rows.add("dynamics", "source", job::dynamics_source_name(job.dynamics_source));
  for (std::size_t i = 0; i < job.modes.size() && i < 12; ++i) {
    const job::ModeSpec& m = job.modes[i];
    const std::string direction =
        m.direction == 'v' ? fmt::format("[{}, {}, {}]", num(m.direction_vector.x()),
                                         num(m.direction_vector.y()), num(m.direction_vector.z()))
                           : std::string(1, m.direction);
    rows.add("dynamics", fmt::format("mode {} ({})", i + 1, direction),
             fmt::format("fn {} Hz, ζ {} %, k {} N/m", num(m.natural_frequency_hz),
                         num(100.0 * m.damping_ratio), num(m.stiffness_n_per_m)));
  }
  if (job.modes.size() > 12)
    rows.add("dynamics", "more modes", std::to_string(job.modes.size() - 12));
  for (const job::FrfFileSpec& f : job.frf_files)
    rows.add("dynamics", "FRF file", f.file.filename().string());
  if (job.posture_library)
    rows.add(
        "dynamics", "posture library",
        fmt::format("{} measured postures (IDW at {})", job.posture_library->postures_rad.size(),
                    job.posture_library->query_source));
}

void add_robot(Rows& rows, const job::RobotSettings& r) {
  if (!r.description.name.empty())
    rows.add("robot", "robot", r.description.name);
  rows.add("robot", "joints", std::to_string(r.description.joints.size()));
  if (!r.posture_rad.empty())
    rows.add("robot", "posture", list(r.posture_rad, kDeg, "°"));
  std::vector<double> stiffness;
  for (const robot::JointProperties& joint : r.description.joints)
    stiffness.push_back(joint.stiffness_nm_per_rad);
  if (!stiffness.empty())
    rows.add("robot", "joint stiffness Kq", list(stiffness, 1.0, "N·m/rad"));
  if (r.map)
    rows.add(
        "robot", "map grid",
        fmt::format("{} × {} × {} points", r.map->counts[0], r.map->counts[1], r.map->counts[2]));
}

void add_stability(Rows& rows, const job::StabilitySettings& s) {
  rows.add("stability", "method", method_name(s.method));
  rows.add("stability", "speeds",
           fmt::format("{} – {} rpm, {} speeds", num(s.speed_from_rad_s * kRpm),
                       num(s.speed_to_rad_s * kRpm), s.speed_count));
  rows.add("stability", "depth max", with_unit(s.depth_max_m * 1e3, "mm"));
  if (s.method != job::StabilitySettings::Method::zoa)
    rows.add("stability", "discretization", std::to_string(s.discretization) + " per tooth");
  if (s.process_damping != job::StabilitySettings::Damping::none)
    rows.add("stability", "process damping",
             fmt::format("{}, Ksp {} N/mm³, wear land {} µm",
                         s.process_damping == job::StabilitySettings::Damping::energy_balance
                             ? "energy balance"
                             : "linear equivalent",
                         num(s.indentation_n_per_m3 * 1e-9), num(s.wear_land_m * 1e6)));
}

void add_toolpath(Rows& rows, const job::ToolpathSettings& t) {
  static constexpr const char* kFormats[] = {"G-code", "APT CL", "KUKA KRL"};
  rows.add("toolpath", "program",
           fmt::format("{} ({})", t.file_text, kFormats[static_cast<int>(t.format)]));
  const Eigen::Vector3d origin = t.program_to_workpiece.translation();
  rows.add("toolpath", "origin",
           fmt::format("[{}, {}, {}] mm", num(origin.x() * 1e3), num(origin.y() * 1e3),
                       num(origin.z() * 1e3)));
  for (const auto& [number, spec] : t.tools)
    rows.add("toolpath", fmt::format("T{}", number),
             fmt::format("{} end mill, D {} mm, {} teeth, helix {}°", tool::type_name(spec.type),
                         num(spec.diameter_m * 1e3), spec.teeth, num(spec.helix_rad * kDeg)));
}

void add_robot_path(Rows& rows, const job::RobotPathJobSettings& r) {
  rows.add("robot path", "redundancy ψ", with_unit(r.redundancy_rad * kDeg, "°"));
  rows.add("robot path", "deflection", r.contact_deflection ? "000's contact boundary" : "static");
  if (r.feed_limits) {
    const job::RobotPathJobSettings::FeedLimits& l = *r.feed_limits;
    std::vector<std::string> caps;
    if (l.force_max_n > 0.0)
      caps.push_back(fmt::format("force {} N", num(l.force_max_n)));
    if (l.torque_max_nm > 0.0)
      caps.push_back(fmt::format("torque {} N·m", num(l.torque_max_nm)));
    if (l.deflection_max_m > 0.0)
      caps.push_back(fmt::format("deflection {} µm", num(l.deflection_max_m * 1e6)));
    if (l.joint_speed_max_rad_s > 0.0)
      caps.push_back(fmt::format("joint speed {} °/s", num(l.joint_speed_max_rad_s * kDeg)));
    std::string text;
    for (const std::string& cap : caps)
      text += (text.empty() ? "" : ", ") + cap;
    if (l.feed_min_m_s > 0.0 || l.feed_max_m_s > 0.0)
      text += fmt::format("; feed {} – {} mm/min",
                          l.feed_min_m_s > 0.0 ? num(l.feed_min_m_s * 6e4) : "…",
                          l.feed_max_m_s > 0.0 ? num(l.feed_max_m_s * 6e4) : "programmed");
    rows.add("robot path", "feed limits", text);
  }
}

}  // namespace

std::string key_inputs_json(const job::Job& job) {
  Rows rows;
  if (job.tool)
    add_tool(rows, *job.tool);
  if (job.cutting)
    add_cutting(rows, *job.cutting);
  if (job.process)
    add_process(rows, *job.process);
  add_dynamics(rows, job);
  if (job.robot)
    add_robot(rows, *job.robot);
  if (job.stability)
    add_stability(rows, *job.stability);
  if (job.simulation) {
    rows.add("simulation", "model", job.simulation->model_name);
    rows.add("simulation", "duration", with_unit(job.simulation->duration_s, "s"));
    rows.add("simulation", "steps per tooth",
             job.simulation->steps_per_tooth_given
                 ? std::to_string(job.simulation->steps_per_tooth)
                 : "automatic (at least " + std::to_string(job.simulation->steps_per_tooth) + ")");
  }
  if (job.workpiece && job.workpiece->pose)
    rows.add("workpiece", "pose [xp, yp, θp]",
             fmt::format("[{} mm, {} mm, {}°]", num(job.workpiece->pose->x_m * 1e3),
                         num(job.workpiece->pose->y_m * 1e3),
                         num(job.workpiece->pose->theta_rad * kDeg)));
  if (!job.path.empty())
    rows.add("path", "points", std::to_string(job.path.size()));
  if (job.atlas) {
    const atlas::AtlasSpec& a = *job.atlas;
    rows.add("atlas", "grid",
             fmt::format("{} × {} × {} points, {} redundancy angles", a.counts[0], a.counts[1],
                         a.counts[2], a.redundancy_rad.size()));
  }
  if (job.toolpath)
    add_toolpath(rows, *job.toolpath);
  if (job.robot_path)
    add_robot_path(rows, *job.robot_path);
  if (job.stock) {
    const job::StockSettings& s = *job.stock;
    rows.add("stock", "box",
             fmt::format("[{}, {}, {}] – [{}, {}, {}] mm", num(s.min_m.x() * 1e3),
                         num(s.min_m.y() * 1e3), num(s.min_m.z() * 1e3), num(s.max_m.x() * 1e3),
                         num(s.max_m.y() * 1e3), num(s.max_m.z() * 1e3)));
    rows.add("stock", "resolution", with_unit(s.resolution_m * 1e3, "mm"));
  }
  for (const io::RecordingSpec& r : job.recordings) {
    std::string what =
        fmt::format("{} ({}", r.file.filename().string(), monitoring::signal_kind_name(r.signal));
    if (r.spindle_rad_s)
      what += fmt::format(", {} rpm", num(*r.spindle_rad_s * 60.0 / (2.0 * std::numbers::pi)));
    if (!r.note.empty())
      what += ", " + r.note;
    rows.add(job.recordings_listed ? "recordings" : "recording", "file", what + ")");
  }
  if (!job.experiments.empty()) {
    int chatter = 0, hammer = 0;
    for (const job::Experiment& e : job.experiments) {
      chatter += e.chatter ? 1 : 0;
      hammer += e.hammer() ? 1 : 0;
    }
    const auto cuts = static_cast<int>(job.experiments.size()) - hammer;
    rows.add("experiments", "tests",
             hammer == 0 ? fmt::format("{} ({} with chatter)", cuts, chatter)
                         : fmt::format("{} cuts ({} with chatter), {} hammer tests", cuts, chatter,
                                       hammer));
  }
  nlohmann::json document = {{"job", job.source.string()}, {"inputs", rows.take()}};
  if (!job.name.empty())
    document["name"] = job.name;
  return document.dump(2) + "\n";
}

}  // namespace robomill::report
