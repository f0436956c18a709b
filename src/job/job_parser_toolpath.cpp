// The `toolpath:` and `stock:` sections of a job (docs/toolpath.md): which
// program, in which dialect, where its zero sits on the part, the cutters of
// its tool numbers, and the stock it cuts. Lengths in mm, angles in deg unless
// written. The program file is read by the command, not here, so that
// `robomill validate` stays fast and a job can be checked before its program
// exists.

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "job_parser_cutting.hpp"
#include "job_parser_toolpath.hpp"
#include "quantity_fields.hpp"

namespace robomill::job::detail {
namespace {

// "G-code", "APT" or "KRL" from the file's extension (case-insensitive);
// nullopt when it says nothing.
std::optional<ToolpathSettings::Format> guess_format(const std::filesystem::path& file) {
  std::string extension = file.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* gcode : {".nc", ".ngc", ".gcode", ".tap", ".cnc", ".iso", ".mpf", ".eia", ".g"})
    if (extension == gcode)
      return ToolpathSettings::Format::gcode;
  for (const char* apt : {".cl", ".cls", ".apt", ".aptsource", ".clt", ".cldata"})
    if (extension == apt)
      return ToolpathSettings::Format::apt;
  if (extension == ".src")
    return ToolpathSettings::Format::krl;
  return std::nullopt;
}

// A frame as KUKA writes it: x, y, z (mm) and A, B, C (deg) with
// R = Rz(A) Ry(B) Rx(C).
Eigen::Isometry3d frame(const std::vector<double>& xyz_m, const std::vector<double>& abc_rad) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(xyz_m[0], xyz_m[1], xyz_m[2]);
  pose.linear() = (Eigen::AngleAxisd(abc_rad[0], Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(abc_rad[1], Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(abc_rad[2], Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  return pose;
}

// A tool number key: "3", "T3" or "t3".
std::optional<int> tool_number(std::string_view key) {
  if (!key.empty() && (key.front() == 'T' || key.front() == 't'))
    key.remove_prefix(1);
  int number = -1;
  const auto [end, error] = std::from_chars(key.data(), key.data() + key.size(), number);
  if (error != std::errc() || end != key.data() + key.size() || number < 0 || number > 99999)
    return std::nullopt;
  return number;
}

void read_tools(SectionReader& tools, ToolpathSettings& settings) {
  for (const std::string& key : tools.keys()) {
    const std::optional<int> number = tool_number(key);
    if (!number)
      tools.fail(key,
                 fmt::format("'{}' is not a tool number; write T1, T2, ... (or 1, 2, ...)", key));
    if (settings.tools.count(*number))
      tools.fail(key, fmt::format("tool {} is given twice", *number));
    auto section = tools.section(key);
    settings.tools.emplace(*number, read_tool_fields(*section));
  }
  tools.finish();
}

void read_work_offsets(SectionReader& offsets, ToolpathSettings& settings) {
  for (const std::string& key : offsets.keys()) {
    std::string upper = key;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    int index = 0;
    if (upper.size() == 3 && upper[0] == 'G' && upper[1] == '5' && upper[2] >= '4' &&
        upper[2] <= '9')
      index = upper[2] - '3';  // G54 → 1 … G59 → 6
    if (index == 0)
      offsets.fail(key, fmt::format("'{}' is not a work offset; write G54 … G59", key));
    const auto xyz = offsets.quantities(key, length_mm(std::nullopt), 3);
    settings.work_offsets_m[index] = Eigen::Vector3d((*xyz)[0], (*xyz)[1], (*xyz)[2]);
  }
  offsets.finish();
}

void read_bases(SectionReader& bases, ToolpathSettings& settings) {
  for (const std::string& key : bases.keys()) {
    int index = 0;
    const auto [end, error] = std::from_chars(key.data(), key.data() + key.size(), index);
    if (error != std::errc() || end != key.data() + key.size() || index < 0 || index > 32)
      bases.fail(key, fmt::format("'{}' is not a base number (BASE_DATA[0 … 32])", key));
    const auto values = bases.quantities(key, dimensionless(), 6);
    const std::vector<double>& v = *values;
    settings.bases[index] =
        frame({v[0] * kMm, v[1] * kMm, v[2] * kMm}, {v[3] * kDeg, v[4] * kDeg, v[5] * kDeg});
  }
  bases.finish();
}

void read_stock(SectionReader& root, Job& job) {
  auto section = root.section("stock");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("stock");
  StockSettings stock;
  stock.line = r.line();
  auto box = r.section("box");
  if (!box)
    r.fail("box", "required: {min: [x, y, z], max: [x, y, z]} in the workpiece frame (mm)");
  box->allow_schema("stock.box");
  const auto min = box->quantities("min", length_mm(std::nullopt), 3);
  const auto max = box->quantities("max", length_mm(std::nullopt), 3);
  if (!min)
    box->fail("min", "required: the box's lower corner [x, y, z] (mm)");
  if (!max)
    box->fail("max", "required: the box's upper corner [x, y, z] (mm)");
  stock.min_m = Eigen::Vector3d((*min)[0], (*min)[1], (*min)[2]);
  stock.max_m = Eigen::Vector3d((*max)[0], (*max)[1], (*max)[2]);
  for (int a = 0; a < 3; ++a) {
    if (!(stock.max_m[a] > stock.min_m[a]))
      box->fail("max", fmt::format("max {} ({:.6g} mm) must exceed min {} ({:.6g} mm)", "xyz"[a],
                                   stock.max_m[a] * 1e3, "xyz"[a], stock.min_m[a] * 1e3));
  }
  box->finish();
  stock.resolution_line = r.line_of("resolution");
  const double default_resolution =
      job.tool ? job.tool->diameter_m / 20.0
               : (job.toolpath && !job.toolpath->tools.empty()
                      ? job.toolpath->tools.begin()->second.diameter_m / 20.0
                      : 0.5e-3);
  stock.resolution_m = r.quantity_or("resolution", length_mm(), default_resolution);
  // The tri-dexel holds three grids of rays; their count bounds memory.
  const Eigen::Vector3d cells = (stock.max_m - stock.min_m) / stock.resolution_m;
  const double rays = cells.x() * cells.y() + cells.y() * cells.z() + cells.x() * cells.z();
  if (rays > 5e7)
    r.fail("resolution",
           fmt::format("{:.4g} mm gives {:.3g} dexel rays over the box (at most 5e7); use {:.3g} "
                       "mm or coarser",
                       stock.resolution_m * 1e3, rays,
                       stock.resolution_m * 1e3 * std::sqrt(rays / 5e7) * 1.01));
  if (auto height_map = r.optional_text("height_map"))
    stock.height_map = job.resolve(*height_map);
  r.finish();
  job.stock = std::move(stock);
}

// `robot_path:` — how the robot follows the program (robot_along_path.hpp).
// The robot, the workpiece pose and the structure are the job's own sections;
// the command checks that they are there.
void read_robot_path(SectionReader& root, Job& job) {
  auto section = root.section("robot_path");
  if (!section)
    return;
  SectionReader& r = *section;
  r.allow_schema("robot_path");
  RobotPathJobSettings s;
  s.line = r.line();
  s.redundancy_rad = r.quantity_or("redundancy", angle_deg(), 0.0);
  s.tolerance = r.quantity_or("tolerance", dimensionless(kPositive, Bound{0.5, true}), 0.02);
  s.max_span = r.integer_or("max_span", 1, 100000, 64);
  s.check_every = r.integer_or("check_every", 0, 1000000, 25);
  s.risk_margin =
      r.quantity_or("risk_margin", dimensionless(Bound{1.0, true}, Bound{10.0, true}), 1.0);
  s.worst_lines = r.integer_or("worst_lines", 1, 1000, 10);
  s.max_chatter_probability =
      r.quantity_or("max_chatter_probability", dimensionless(kPositive, Bound{1.0, false}), 0.05);
  if (r.has("deflection"))
    s.contact_deflection = r.choice("deflection", {"static", "contact"}) == "contact";
  if (auto search = r.section("redundancy_search")) {
    search->allow_schema("robot_path.redundancy_search");
    const double from = search->quantity("from", angle_deg());
    const double to = search->quantity("to", angle_deg());
    const int count = search->integer("count", 1, 721);
    s.redundancy_per_line = search->boolean_or("per_line", false);
    s.redundancy_joint_speed_rad_s = search->quantity_or(
        "joint_speed_max", field(dimensions::angular_speed, kDeg, "deg/s", kPositive), 0.0);
    if (count > 1 && !(to > from))
      search->fail("to", fmt::format("must exceed from ({:g} deg) when count > 1, got {:g} deg",
                                     from / kDeg, to / kDeg));
    search->finish();
    for (int i = 0; i < count; ++i)
      s.redundancy_search_rad.push_back(count == 1 ? from : from + (to - from) * i / (count - 1));
  }
  if (auto limits = r.section("feed_limits")) {
    limits->allow_schema("robot_path.feed_limits");
    RobotPathJobSettings::FeedLimits l;
    l.job_line = limits->line();
    const QuantityField feed = field(dimensions::speed, kMm / 60.0, "mm/min", kPositive);
    l.force_max_n =
        limits->quantity_or("force_max", field(dimensions::force, 1.0, "N", kPositive), 0.0);
    l.torque_max_nm =
        limits->quantity_or("torque_max", field(dimensions::torque, 1.0, "N*m", kPositive), 0.0);
    l.deflection_max_m = limits->quantity_or("deflection_max",
                                             field(dimensions::length, 1e-6, "um", kPositive), 0.0);
    l.joint_speed_max_rad_s = limits->quantity_or(
        "joint_speed_max", field(dimensions::angular_speed, kDeg, "deg/s", kPositive), 0.0);
    l.feed_min_m_s = limits->quantity_or("feed_min", feed, 0.0);
    l.feed_max_m_s = limits->quantity_or("feed_max", feed, 0.0);
    if (l.force_max_n == 0.0 && l.torque_max_nm == 0.0 && l.deflection_max_m == 0.0 &&
        l.joint_speed_max_rad_s == 0.0)
      limits->fail("force_max",
                   "give at least one cap: force_max, torque_max, deflection_max "
                   "or joint_speed_max");
    if (l.feed_max_m_s > 0.0 && l.feed_max_m_s < l.feed_min_m_s)
      limits->fail("feed_max", fmt::format("must be at least feed_min ({:g} mm/min), got {:g} "
                                           "mm/min",
                                           l.feed_min_m_s * 6e4, l.feed_max_m_s * 6e4));
    limits->finish();
    s.feed_limits = l;
  }
  if (auto offset = r.section("offset")) {
    offset->allow_schema("robot_path.offset");
    RobotPathJobSettings::Offset o;
    o.line = offset->line();
    if (offset->has("measure")) {
      const std::string measure =
          offset->choice("measure", {"peak", "vibration", "rms", "mean", "startup"});
      o.measure = measure == "vibration" ? planning::OffsetMeasure::vibration
                  : measure == "rms"     ? planning::OffsetMeasure::rms
                  : measure == "mean"    ? planning::OffsetMeasure::mean
                  : measure == "startup" ? planning::OffsetMeasure::startup
                                         : planning::OffsetMeasure::peak;
    }
    if (offset->has("harmonics"))
      o.harmonics = offset->integer("harmonics", 1, 2000);
    if (offset->has("samples"))
      o.samples = offset->integer("samples", 8, 100000);
    if (o.harmonics && o.samples && *o.samples < 2 * *o.harmonics + 1)
      offset->fail("samples", fmt::format("must be at least 2 harmonics + 1 = {} (Nyquist), got {}",
                                          2 * *o.harmonics + 1, *o.samples));
    offset->finish();
    s.offset = o;
  }
  if (auto compensation = r.section("compensation")) {
    compensation->allow_schema("robot_path.compensation");
    RobotPathJobSettings::Compensation c;
    c.line = compensation->line();
    c.floor = compensation->boolean_or("floor", false);
    c.min_offset_m = compensation->quantity_or(
        "min_offset", field(dimensions::length, 1e-6, "um", Bound{0.0, true}), 1e-6);
    c.tolerance_m = compensation->quantity_or(
        "tolerance", field(dimensions::length, 1e-6, "um", kPositive), 2e-6);
    compensation->finish();
    s.compensation = c;
  }
  r.finish();
  job.robot_path = s;
}

}  // namespace

void read_toolpath(SectionReader& root, Job& job) {
  if (auto section = root.section("toolpath")) {
    SectionReader& r = *section;
    r.allow_schema("toolpath");
    ToolpathSettings s;
    s.line = r.line();
    s.file_line = r.line_of("file");
    const auto file = r.optional_text("file");
    if (!file)
      r.fail("file", "required: the program the cell runs (G-code, APT CL or KRL .src)");
    s.file_text = *file;
    s.file = job.resolve(*file);
    const auto guessed = guess_format(s.file);
    if (r.has("format")) {
      const std::string format = r.choice("format", {"gcode", "apt", "krl"});
      s.format = format == "apt"   ? ToolpathSettings::Format::apt
                 : format == "krl" ? ToolpathSettings::Format::krl
                                   : ToolpathSettings::Format::gcode;
    } else if (guessed) {
      s.format = *guessed;
    } else {
      r.fail("file", fmt::format("cannot tell the dialect of '{}' from its extension; add "
                                 "format: gcode, apt or krl",
                                 *file));
    }
    if (const auto origin = r.quantities("origin", length_mm(std::nullopt), 3)) {
      std::vector<double> abc = {0.0, 0.0, 0.0};
      if (const auto orientation = r.quantities("orientation", angle_deg(), 3))
        abc = *orientation;
      s.program_to_workpiece = frame(*origin, abc);
    } else if (const auto orientation = r.quantities("orientation", angle_deg(), 3)) {
      s.program_to_workpiece = frame({0.0, 0.0, 0.0}, *orientation);
    }
    s.tools_line = r.line_of("tools");
    if (auto tools = r.section("tools"))
      read_tools(*tools, s);
    s.spacing_m = r.quantity_or("spacing", length_mm(), 0.0);
    s.rapid_speed_m_s = r.quantity_or(
        "rapid_speed", field(dimensions::speed, kMm / 60.0, "mm/min", kPositive), 0.5);
    const auto spindle =
        r.optional_quantity("spindle", field(dimensions::angular_speed, kRpm, "rpm", kPositive));
    if (spindle)
      s.spindle_rad_s = *spindle;
    else if (job.process)
      s.spindle_rad_s = job.process->spindle_rad_s;
    s.force_steps_per_tooth = r.integer_or("steps_per_tooth", 4, 10000, 32);
    s.block_samples = static_cast<std::size_t>(r.integer_or("block_samples", 16, 1 << 20, 4096));
    const double max_mb =
        r.quantity_or("max_size", dimensionless(kPositive, Bound{4096.0, true}), 64.0);
    s.max_bytes = static_cast<std::size_t>(max_mb * 1024.0 * 1024.0);
    if (auto offsets = r.section("work_offsets"))
      read_work_offsets(*offsets, s);
    if (auto dat = r.optional_text("dat"))
      s.dat_file = job.resolve(*dat);
    else if (s.format == ToolpathSettings::Format::krl)
      s.dat_file = std::filesystem::path(s.file).replace_extension(".dat");
    if (auto bases = r.section("bases"))
      read_bases(*bases, s);
    s.tool_direction = r.choice("tool_direction", {"x", "z"}, "x")[0];
    if (r.has("units"))
      s.units = r.choice("units", {"mm", "inch"}) == "inch" ? ToolpathSettings::Units::inch
                                                            : ToolpathSettings::Units::mm;
    const bool krl = s.format == ToolpathSettings::Format::krl;
    if (!krl && (r.has("dat") || r.has("bases") || r.has("tool_direction")))
      r.fail(r.has("dat")     ? "dat"
             : r.has("bases") ? "bases"
                              : "tool_direction",
             "only for KRL programs (format: krl)");
    if (s.format != ToolpathSettings::Format::gcode && r.has("work_offsets"))
      r.fail("work_offsets", "only for G-code programs (format: gcode)");
    if (s.format != ToolpathSettings::Format::apt && r.has("units"))
      r.fail("units",
             "only for APT / CL programs (format: apt); G-code says G20/G21, KRL is in mm");
    r.finish();
    if (s.tools.empty() && !job.tool)
      r.fail_here(
          "the program's cutters are needed: give the job a tool: section, or "
          "toolpath.tools with a cutter per tool number");
    job.toolpath = std::move(s);
  }
  read_stock(root, job);
  read_robot_path(root, job);
}

}  // namespace robomill::job::detail
