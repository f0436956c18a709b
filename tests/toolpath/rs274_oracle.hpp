#pragma once
// LinuxCNC's standalone rs274ngc interpreter `rs274` (Debian package
// linuxcnc-uspace) as an oracle for read_gcode, shared by
// test_gcode_oracle.cpp (our corpus) and test_gcode_real_programs.cpp (the
// example programs LinuxCNC ships).
//
// run_rs274 feeds a program to rs274 and replays the canonical machining
// calls it prints (STRAIGHT_TRAVERSE, STRAIGHT_FEED, ARC_FEED, DWELL,
// SET_FEED_RATE, ...) into end points, arc centres and turns, feeds, spindle
// speeds, tools and source lines; first_difference compares them with
// read_gcode's moves:
//  * rs274 prints 4 decimals in the program's unit, so positions and centres
//    agree to half a unit of the last printed digit (5e-5 mm or 5e-5 in), not
//    to 1e-6 mm;
//  * rs274 tags each call with the block's N number, so the program is fed
//    to it with every line numbered N<line> and the tags give source lines;
//  * rs274 reads work offsets from a parameter file (in inches without an
//    INI file); we give it G55 = (4, 2, -0.5) in and read_gcode the same
//    offset in metres (oracle_options), and compare in the G54 frame;
//  * zero-length straight moves, which rs274 prints at the start of some
//    cycles and read_gcode drops, are skipped.

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::test::rs274 {

namespace fs = std::filesystem;
using robomill::toolpath::MotionKind;
using robomill::toolpath::Move;

inline constexpr double kMetresPerInch = 0.0254;
inline const Eigen::Vector3d kG55OffsetInch(4.0, 2.0, -0.5);

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::optional<std::string> find_rs274() {
  if (FILE* pipe = popen("command -v rs274 2>/dev/null", "r")) {
    std::array<char, 512> buffer{};
    std::string path;
    while (fgets(buffer.data(), buffer.size(), pipe))
      path += buffer.data();
    pclose(pipe);
    while (!path.empty() && (path.back() == '\n' || path.back() == '\r'))
      path.pop_back();
    if (!path.empty())
      return path;
  }
  if (fs::exists("/usr/bin/rs274"))
    return "/usr/bin/rs274";
  return std::nullopt;
}

/// The program with every block numbered by its line (N<line>), so that
/// rs274's N tags name source lines. Comment, %, O and blank lines stay.
inline std::string number_lines(const std::string& text) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::size_t i = line.find_first_not_of(" \t");
    std::string prefix;
    if (i != std::string::npos && line[i] == '/') {
      prefix = line.substr(0, i + 1);
      line = line.substr(i + 1);
      i = line.find_first_not_of(" \t");
    }
    const char first = i == std::string::npos ? '\r' : line[i];
    if (std::string("%(;Oo:\r").find(first) != std::string::npos) {
      out << prefix << line << '\n';
      continue;
    }
    if (first == 'N' || first == 'n') {
      std::size_t j = i + 1;
      while (j < line.size() && std::isdigit(static_cast<unsigned char>(line[j])))
        ++j;
      line = line.substr(0, i).append("N").append(std::to_string(number)).append(line.substr(j));
    } else {
      line = std::string("N").append(std::to_string(number)).append(" ").append(line);
    }
    out << prefix << line << '\n';
  }
  return out.str();
}

/// One motion as rs274 reports it, in metres in the G54 frame.
struct CanonMove {
  MotionKind kind = MotionKind::linear;
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // arcs, in the start's plane
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   // arcs
  double sweep_rad = 0.0;                              // arcs
  double feed_m_s = 0.0;
  double feed_tolerance_m_s = 0.0;
  double spindle_rad_s = 0.0;
  int tool = 0;
  double dwell_s = 0.0;
  int line = 0;
  double tolerance_m = 0.0;  // half the last printed digit
};

inline std::vector<double> numbers_in(const std::string& args) {
  std::vector<double> values;
  std::string token;
  std::istringstream in(args);
  while (std::getline(in, token, ',')) {
    std::istringstream field(token);
    double value = 0.0;
    while (field >> value)  // "0.0000 0.0000" in a few calls: take every number
      values.push_back(value);
  }
  return values;
}

/// Replays rs274's canonical calls into moves.
class CanonReplay {
 public:
  void call(const std::string& name, const std::string& args, int line) {
    const std::vector<double> v = numbers_in(args);
    if (name == "USE_LENGTH_UNITS") {
      unit_m_ = args.find("INCHES") != std::string::npos ? kMetresPerInch : 1e-3;
    } else if (name == "SET_G5X_OFFSET") {
      offset_m_ = Eigen::Vector3d(v.at(1), v.at(2), v.at(3)) * unit_m_;
    } else if (name == "SELECT_PLANE") {
      plane_ = args.find("XZ") != std::string::npos   ? std::array<int, 3>{2, 0, 1}
               : args.find("YZ") != std::string::npos ? std::array<int, 3>{1, 2, 0}
                                                      : std::array<int, 3>{0, 1, 2};
    } else if (name == "SET_FEED_MODE") {
      per_revolution_ = v.at(1) != 0.0;
    } else if (name == "SET_FEED_RATE") {
      feed_units_ = v.at(0) * unit_m_;
    } else if (name == "SET_SPINDLE_SPEED") {
      rpm_ = v.at(1);
    } else if (name == "START_SPINDLE_CLOCKWISE") {
      direction_ = 1;
    } else if (name == "START_SPINDLE_COUNTERCLOCKWISE") {
      direction_ = -1;
    } else if (name == "STOP_SPINDLE_TURNING") {
      direction_ = 0;
    } else if (name == "CHANGE_TOOL") {
      tool_ = static_cast<int>(v.at(0));
    } else if (name == "STRAIGHT_TRAVERSE" || name == "STRAIGHT_FEED") {
      const Eigen::Vector3d end = Eigen::Vector3d(v.at(0), v.at(1), v.at(2)) * unit_m_ + offset_m_;
      // rs274 prints a move for `G1` alone and at the start of some cycles;
      // read_gcode drops moves of no length. Equal within the printed digits
      // (after a G20/G21 switch the rounded position moves by < 1e-4 units).
      const double printed_m = std::max(0.51e-4 * unit_m_, position_tolerance_m_) + 1e-12;
      if ((end - position_m_).lpNorm<Eigen::Infinity>() > printed_m) {
        CanonMove move = base(line);
        move.kind = name == "STRAIGHT_TRAVERSE" ? MotionKind::rapid : MotionKind::linear;
        if (move.kind == MotionKind::rapid)
          move.feed_m_s = move.feed_tolerance_m_s = 0.0;
        move.end_m = end;
        moves.push_back(move);
      }
      position_m_ = end;
      position_tolerance_m_ = 0.51e-4 * unit_m_;
    } else if (name == "ARC_FEED") {
      arc(v, line);
    } else if (name == "DWELL") {
      CanonMove move = base(line);
      move.kind = MotionKind::dwell;
      move.end_m = position_m_;
      move.dwell_s = v.at(0);
      move.feed_m_s = move.feed_tolerance_m_s = 0.0;
      moves.push_back(move);
    }
  }

  std::vector<CanonMove> moves;

 private:
  CanonMove base(int line) const {
    CanonMove move;
    move.line = line;
    move.tool = tool_;
    move.spindle_rad_s = direction_ * rpm_ * 2.0 * std::numbers::pi / 60.0;
    const double scale = per_revolution_ ? rpm_ : 1.0;
    move.feed_m_s = feed_units_ * scale / 60.0;
    move.feed_tolerance_m_s = 0.6e-4 * unit_m_ * scale / 60.0 + 1e-12;
    move.tolerance_m = 0.51e-4 * unit_m_ + 1e-12;
    return move;
  }

  // ARC_FEED(first_end, second_end, first_centre, second_centre, rotation,
  // axis_end, a, b, c): rotation > 0 counter-clockwise from the first axis
  // to the second, |rotation| turns begun.
  void arc(const std::vector<double>& v, int line) {
    const auto [first, second, axis] = plane_;
    CanonMove move = base(line);
    move.kind = MotionKind::arc;
    Eigen::Vector3d end = Eigen::Vector3d::Zero();
    end[first] = v.at(0);
    end[second] = v.at(1);
    end[axis] = v.at(5);
    move.end_m = end * unit_m_ + offset_m_;
    move.centre_m = position_m_;
    move.centre_m[first] = v.at(2) * unit_m_ + offset_m_[first];
    move.centre_m[second] = v.at(3) * unit_m_ + offset_m_[second];
    move.normal = Eigen::Vector3d::Zero();
    move.normal[axis] = 1.0;
    const int rotation = static_cast<int>(v.at(4));
    const double a0 = std::atan2(position_m_[second] - move.centre_m[second],
                                 position_m_[first] - move.centre_m[first]);
    const double a1 = std::atan2(move.end_m[second] - move.centre_m[second],
                                 move.end_m[first] - move.centre_m[first]);
    const double two_pi = 2.0 * std::numbers::pi;
    double sweep = a1 - a0;  // counter-clockwise, brought into (0, 2π]
    while (sweep <= 1e-9)
      sweep += two_pi;
    while (sweep > two_pi + 1e-9)
      sweep -= two_pi;
    if (rotation < 0)
      sweep = sweep >= two_pi - 1e-9 ? -two_pi : sweep - two_pi;
    const int extra = std::abs(rotation) - 1;
    move.sweep_rad = sweep + (rotation < 0 ? -1.0 : 1.0) * two_pi * extra;
    moves.push_back(move);
    position_m_ = move.end_m;
    position_tolerance_m_ = 0.51e-4 * unit_m_;
  }

  double unit_m_ = 1e-3;
  Eigen::Vector3d offset_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_m_ = Eigen::Vector3d::Zero();
  double position_tolerance_m_ = 0.0;  // of the printed position
  std::array<int, 3> plane_{0, 1, 2};
  bool per_revolution_ = false;
  double feed_units_ = 0.0;
  double rpm_ = 0.0;
  int direction_ = 0;
  int tool_ = 0;
};

struct OracleRun {
  int status = -1;
  std::string output;
  std::vector<CanonMove> moves;
};

inline OracleRun run_rs274(const std::string& rs274, const std::string& program_text,
                           const std::string& stem) {
  // A directory of its own per run (runs may go in parallel threads), named
  // without characters the shell command below would have to quote.
  static std::atomic<int> runs{0};
  std::string name = stem;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
      c = '_';
  const fs::path dir =
      fs::temp_directory_path() / ("robomill-gcode-oracle-" + std::to_string(::getpid()) + "-" +
                                   std::to_string(runs++) + "-" + name);
  fs::create_directories(dir);
  const fs::path program = dir / "program.ngc";
  const fs::path vars = dir / "oracle.var";
  const fs::path tools = dir / "oracle.tbl";
  std::ofstream(program, std::ios::binary) << number_lines(program_text);
  // G55 (parameters 5241-5243) in inches: rs274 without an INI works in inches.
  std::ofstream(vars) << "5161 0\n5162 0\n5163 0\n5241 " << kG55OffsetInch.x() << "\n5242 "
                      << kG55OffsetInch.y() << "\n5243 " << kG55OffsetInch.z() << "\n";
  // Tools 0-99, all of length 0: tool lengths do not change printed points.
  {
    std::ofstream table(tools);
    for (int tool = 1; tool < 100; ++tool)
      table << "T" << tool << " P" << tool << " Z0 D6 ;\n";
  }
  OracleRun run;
  // rs274 keeps its tool table in $HOME/.tool.mmap: runs sharing one HOME
  // (parallel threads, ctest -j) corrupt each other's (bus errors, "tool not
  // found"), so each run gets its directory as HOME.
  const std::string command = "cd '" + dir.string() + "' && HOME='" + dir.string() + "' '" + rs274 +
                              "' -t oracle.tbl -v oracle.var -g program.ngc 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr)
    return run;
  std::array<char, 4096> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe))
    run.output += buffer.data();
  run.status = pclose(pipe);
  fs::remove_all(dir);

  static const std::regex kCall(R"(^\s*\d+\s+N([0-9]+|\.+)\s+([A-Z_0-9]+)\((.*)\)\s*$)");
  CanonReplay replay;
  std::istringstream lines(run.output);
  std::string text;
  while (std::getline(lines, text)) {
    std::smatch match;
    if (!std::regex_match(text, match, kCall))
      continue;
    const std::string tag = match[1];
    const int line = tag.find('.') == std::string::npos ? std::stoi(tag) : 0;
    replay.call(match[2], match[3], line);
  }
  run.moves = std::move(replay.moves);
  return run;
}

inline std::string describe(const Eigen::Vector3d& p) {
  std::ostringstream out;
  out << "(" << p.x() * 1e3 << ", " << p.y() * 1e3 << ", " << p.z() * 1e3 << ") mm";
  return out.str();
}

/// The options read_gcode gets for a program rs274 runs with run_rs274's
/// parameter file: G55 as there, home Z at the machine origin.
inline robomill::io::GcodeOptions oracle_options(const std::string& source_name) {
  robomill::io::GcodeOptions options;
  options.source_name = source_name;
  options.work_offsets_m[2] = kG55OffsetInch * kMetresPerInch;
  options.home_z_m = 0.0;  // rs274's G28 home (parameters 5161-5163) is the machine origin
  return options;
}

/// The first way read_gcode's moves differ from rs274's, in words; empty when
/// every move agrees (kind, source line, chaining, end point, feed, spindle,
/// tool, dwell, a vertical tool axis, arc centre and signed sweep) to the
/// printed precision.
inline std::string first_difference(const robomill::toolpath::Program& program,
                                    const std::vector<CanonMove>& expected_moves) {
  std::ostringstream out;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  const std::size_t count = std::min(program.moves.size(), expected_moves.size());
  for (std::size_t n = 0; n < count; ++n) {
    const CanonMove& expected = expected_moves[n];
    const Move& move = program.moves[n];
    auto differs = [&](const std::string& what) {
      out << "move " << n << " (rs274 line " << expected.line << ", ours line " << move.line
          << ", end " << describe(move.end_m) << " vs rs274 " << describe(expected.end_m)
          << "): " << what;
      return out.str();
    };
    if (move.kind != expected.kind)
      return differs("kind " + std::to_string(static_cast<int>(move.kind)) + " vs rs274 " +
                     std::to_string(static_cast<int>(expected.kind)));
    if (move.line != expected.line)
      return differs("source line differs");
    if ((move.start_m - start).norm() > 1e-12)
      return differs("moves are not chained");
    if ((move.end_m - expected.end_m).lpNorm<Eigen::Infinity>() > expected.tolerance_m)
      return differs("end point differs");
    if (!(std::abs(move.feed_m_s - expected.feed_m_s) <= expected.feed_tolerance_m_s))
      return differs("feed " + std::to_string(move.feed_m_s) + " m/s vs rs274 " +
                     std::to_string(expected.feed_m_s) + " m/s");
    if (!(std::abs(move.spindle_rad_s - expected.spindle_rad_s) <= 1e-9))
      return differs("spindle " + std::to_string(move.spindle_rad_s) + " rad/s vs rs274 " +
                     std::to_string(expected.spindle_rad_s) + " rad/s");
    if (move.tool != expected.tool)
      return differs("tool " + std::to_string(move.tool) + " vs rs274 " +
                     std::to_string(expected.tool));
    if (!(std::abs(move.dwell_s - expected.dwell_s) <= 0.6e-4))
      return differs("dwell " + std::to_string(move.dwell_s) + " s vs rs274 " +
                     std::to_string(expected.dwell_s) + " s");
    if (!move.axis_start.isApprox(Eigen::Vector3d::UnitZ()))
      return differs("the tool axis is not +Z");
    if (expected.kind == MotionKind::arc) {
      if ((move.centre_m - expected.centre_m).lpNorm<Eigen::Infinity>() > expected.tolerance_m)
        return differs("arc centre " + describe(move.centre_m) + " vs rs274 " +
                       describe(expected.centre_m));
      const Eigen::Vector3d ours = move.normal * move.sweep_rad;
      const Eigen::Vector3d theirs = expected.normal * expected.sweep_rad;
      // 2e-3 rad, or on arcs so small that rounding rs274's printed start, end
      // and centre (each by up to √2 × tolerance in the plane) turns its
      // sweep by more: at most 4√2 × tolerance / radius.
      const Eigen::Vector3d radial = move.start_m - move.centre_m;
      const double radius = (radial - radial.dot(move.normal) * move.normal).norm();
      const double sweep_tolerance =
          std::max(2e-3, 4.0 * std::numbers::sqrt2 * expected.tolerance_m / radius);
      if (!((ours - theirs).norm() <= sweep_tolerance))
        return differs("sweep " + std::to_string(move.sweep_rad) + " rad vs rs274 " +
                       std::to_string(expected.sweep_rad) + " rad");
    }
    start = move.end_m;
  }
  if (program.moves.size() != expected_moves.size())
    out << program.moves.size() << " moves vs rs274 " << expected_moves.size() << " (the first "
        << count << " agree)";
  return out.str();
}

}  // namespace robomill::test::rs274
