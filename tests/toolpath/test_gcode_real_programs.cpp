// read_gcode on programs written by others: the example programs Debian's
// linuxcnc-uspace package ships (/usr/share/linuxcnc/ncfiles and
// /usr/share/doc/linuxcnc/examples, about 330 .ngc files: mill and lathe
// programs, plasma, probing, ngcgui and remap subroutine libraries, 5-axis
// demos). Every file found at run time is read:
//  * read_gcode accepts it, or refuses it with an InputError that names the
//    line (0 only for a whole-file problem) and starts with the word it
//    refuses; any other exception fails the test, and so does a non-finite
//    number or a tool axis that is not the unit +Z in an accepted program;
//  * every refusal belongs to one of the classes the dialect notes at the top
//    of src/io/gcode_reader.cpp list (kRefusalClasses below), and is tallied;
//  * a program we accept and rs274 runs with exit status 0 is compared with
//    rs274 move by move, as test_gcode_oracle.cpp does (rs274_oracle.hpp);
//    a difference fails the test unless the file is listed in
//    kExpectedDifferences with the dialect choice that explains it (and a
//    listed file that agrees fails too, so the list stays true).
// A summary (files, accepted, compared, matched, refusals by class) is
// printed and recorded as test properties; docs/toolpath.md quotes it.
// Without the package installed the test is skipped with a message.
//
// GcodeOthers: the programs in tests/toolpath/gcode/others/ (FreeCAD's
// linuxcnc, centroid and grbl posts, LinuxCNC's examples; sources and
// licences in the README there) are read with numbers from each program
// checked by hand, and compared with rs274 where it is installed.

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <future>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <typeinfo>
#include <utility>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "toolpath/rs274_oracle.hpp"

namespace test_gcode_real_programs_cpp {

namespace {

namespace fs = std::filesystem;
using robomill::InputError;
using robomill::toolpath::Program;
using namespace robomill::test::rs274;

/// Where the package puts its example programs.
const std::vector<fs::path> kRoots{"/usr/share/linuxcnc/ncfiles",
                                   "/usr/share/doc/linuxcnc/examples"};

/// rs274 is run on programs up to this size (the larger ones are 5-axis
/// demos read_gcode refuses anyway); read_gcode reads every file.
constexpr std::uintmax_t kMaxOracleBytes = 200 * 1024;

/// The refusal classes of gcode_reader.cpp's dialect notes, each recognised
/// by a part of its message.
struct RefusalClass {
  std::string_view name;
  std::string_view message_part;
};

const std::vector<RefusalClass> kRefusalClasses{
    {"subroutines and O-word control flow (O, M98/M99, G65)", "subroutines and O-word"},
    {"subroutines and O-word control flow (O, M98/M99, G65)", "an O word must stand alone"},
    {"subroutines and O-word control flow (O, M98/M99, G65)", "subprogram calls"},
    {"subroutines and O-word control flow (O, M98/M99, G65)", "macro calls"},
    {"parameters and expressions (#, [ ])", "parameters, variables and expressions"},
    {"cutter compensation (G41/G42)", "cutter compensation is not modelled"},
    {"inverse-time feed (G93)", "inverse-time feed"},
    {"frame changes (G92, G10, G52)", "coordinate-system shifts"},
    {"frame changes (G68, G51, G16, polar @ ^)", "rotated, scaled, mirrored or polar"},
    {"frame changes (G68, G51, G16, polar @ ^)", "polar coordinates (LinuxCNC's"},
    {"5-axis and dynamic tool length (G43.1, G43.4)", "5-axis tool-length"},
    {"unsupported canned cycles (G33, G76, G84-G89)", "this canned cycle"},
    {"rotary and extra axes (A B C U V W)", "rotary and extra axes"},
    {"unknown G code", "unknown G code"},
    {"unknown M code", "unknown M code"},
    {"unknown letter or character", "unknown word"},
    {"unknown letter or character", "unexpected character"},
    {"machine coordinates (G53 other than home)", "machine coordinates are not known"},
    {"cycles outside G17", "drilling cycles are read in G17 only"},
    {"feed move with no F", "without a feed rate"},
    {"axis words with no motion mode", "no motion mode is in force"},
    {"word no code in the block uses", "no code in this block uses"},
    {"word repeated in a block", "a word may appear once"},
    {"two codes of one modal group", "in one block:"},
    {"arc end point off the circle", "the end point is not on the arc"},
    {"program larger than max_bytes", "more than the limit of"},
    {"malformed line (unclosed comment, letter without a number)",
     "opens a comment that the line does not close"},
    {"malformed line (unclosed comment, letter without a number)", "a number must follow"},
    {"malformed line (unclosed comment, letter without a number)", ": not a number"},
};

/// The class of a refusal, or nullopt for a message on no documented list.
std::optional<std::string_view> refusal_class(const std::string& message) {
  for (const RefusalClass& c : kRefusalClasses)
    if (message.find(c.message_part) != std::string::npos)
      return c.name;
  return std::nullopt;
}

/// Accepted programs on which read_gcode deliberately differs from rs274,
/// by their name (path under /usr/share), with the dialect choice that
/// explains it.
const std::map<std::string, std::string, std::less<>> kExpectedDifferences{};

struct Outcome {
  std::string name;  // path under /usr/share
  fs::path path;
  std::uintmax_t bytes = 0;
  bool accepted = false;
  std::string refusal_word;   // the refused word (first token of the message)
  std::string refusal_class;  // kRefusalClasses name
  std::vector<std::string> failures;
  // The rs274 comparison (accepted programs only).
  bool compared = false;  // rs274 ran it with status 0
  std::string difference;
  std::size_t moves = 0;
};

std::vector<fs::path> example_programs() {
  std::vector<fs::path> paths;
  for (const fs::path& root : kRoots) {
    std::error_code error;
    if (!fs::is_directory(root, error))
      continue;
    for (fs::recursive_directory_iterator it(root, error), end; !error && it != end;
         it.increment(error)) {
      if (it->path().extension() == ".ngc" && fs::is_regular_file(it->path(), error))
        paths.push_back(it->path());
    }
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

/// The text of line `number` (1-based) of `text`, or empty.
std::string line_of(const std::string& text, int number) {
  std::istringstream in(text);
  std::string line;
  for (int n = 1; n <= number && std::getline(in, line); ++n)
    if (n == number)
      return line;
  return {};
}

std::string upper_without_blanks(std::string_view text) {
  std::string out;
  for (const char c : text)
    if (c != ' ' && c != '\t' && c != '\r')
      out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

/// What the tally counts of a refused word: a G or M code as written (G41,
/// M98), otherwise its first character (O, #, A, ^ ...).
std::string word_key(const std::string& word) {
  if (word.empty())
    return "(none)";
  if (word[0] == '\'' && word.size() >= 2)
    return word.substr(1, 1);
  if (word[0] != 'G' && word[0] != 'M')
    return word.substr(0, 1);
  const std::size_t end = word.find_first_not_of("0123456789.", 1);
  return word.substr(0, end);
}

/// The refusal's message without the "name (line N): " prefix.
std::string reason_of(const InputError& error) {
  const std::string what = error.what();
  const std::string prefix =
      error.field() + (error.line() > 0 ? " (line " + std::to_string(error.line()) + ")" : "") +
      ": ";
  return what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
}

/// Reads one program and checks what read_gcode makes of it.
Outcome read_one(const fs::path& path) {
  Outcome outcome;
  outcome.path = path;
  outcome.name = fs::relative(path, "/usr/share").generic_string();
  std::error_code error;
  outcome.bytes = fs::file_size(path, error);
  const std::string text = read_text(path);
  try {
    const Program program = robomill::io::read_gcode(text, oracle_options(outcome.name));
    outcome.accepted = true;
    outcome.moves = program.moves.size();
    for (const auto& move : program.moves) {
      const bool finite = move.start_m.allFinite() && move.end_m.allFinite() &&
                          move.centre_m.allFinite() && move.normal.allFinite() &&
                          std::isfinite(move.sweep_rad) && std::isfinite(move.feed_m_s) &&
                          std::isfinite(move.spindle_rad_s) && std::isfinite(move.dwell_s);
      const bool vertical = (move.axis_start - Eigen::Vector3d::UnitZ()).norm() <= 1e-12 &&
                            (move.axis_end - Eigen::Vector3d::UnitZ()).norm() <= 1e-12;
      if (!finite || !vertical) {
        const std::string what = finite ? "the tool axis is not +Z" : "a number is not finite";
        outcome.failures.push_back("line " + std::to_string(move.line) + ": " + what);
        break;
      }
    }
  } catch (const InputError& refusal) {
    const std::string reason = reason_of(refusal);
    outcome.refusal_word = reason.substr(0, reason.find_first_of(": "));
    const std::optional<std::string_view> known = refusal_class(reason);
    outcome.refusal_class = known ? std::string(*known) : "(undocumented)";
    if (!known)
      outcome.failures.push_back("refused for a reason on no documented list: " +
                                 std::string(refusal.what()));
    // Line 0 is for whole-file problems only (a program over max_bytes).
    const bool whole_file = reason.find("more than the limit of") != std::string::npos;
    const int line_count = static_cast<int>(std::count(text.begin(), text.end(), '\n')) + 1;
    if (whole_file ? refusal.line() != 0 : refusal.line() < 1 || refusal.line() > line_count)
      outcome.failures.push_back("the refusal names line " + std::to_string(refusal.line()) +
                                 ", not a line of the program: " + refusal.what());
    // The word comes first, as written in the line (blanks and case aside).
    std::string word = upper_without_blanks(outcome.refusal_word);
    if (word.size() >= 2 && word.front() == '\'' && word.back() == '\'')
      word = word.substr(1, word.size() - 2);
    if (!whole_file && word.empty()) {
      outcome.failures.push_back("the refusal names no word: " + std::string(refusal.what()));
    } else if (!whole_file && upper_without_blanks(line_of(text, refusal.line())).find(word) ==
                                  std::string::npos) {
      outcome.failures.push_back("the refusal does not start with a word of line " +
                                 std::to_string(refusal.line()) + ": " + refusal.what());
    }
  } catch (const std::exception& other) {
    outcome.failures.push_back(std::string("not an InputError: ") + typeid(other).name() + ": " +
                               other.what());
  }
  return outcome;
}

void compare_with_rs274(Outcome& outcome, const std::string& rs274) {
  const std::string text = read_text(outcome.path);
  const OracleRun oracle = run_rs274(rs274, text, outcome.path.stem().string());
  const bool crashed = oracle.status == -1 || WIFSIGNALED(oracle.status) ||
                       (WIFEXITED(oracle.status) && WEXITSTATUS(oracle.status) >= 128);
  if (crashed)
    outcome.failures.push_back("rs274 did not run (status " + std::to_string(oracle.status) +
                               "):\n" + oracle.output);
  if (oracle.status != 0)
    return;  // rs274 refuses it too (or stops): nothing to compare
  outcome.compared = true;
  const Program program = robomill::io::read_gcode(text, oracle_options(outcome.name));
  outcome.difference = first_difference(program, oracle.moves);
}

TEST(GcodeRealPrograms, LinuxCncExamplesAreReadOrRefusedAndMatchRs274) {
  const std::vector<fs::path> paths = example_programs();
  if (paths.empty())
    GTEST_SKIP() << "no LinuxCNC example programs (Debian package linuxcnc-uspace) under "
                    "/usr/share/linuxcnc/ncfiles or /usr/share/doc/linuxcnc/examples: not run";
  const std::optional<std::string> rs274 = find_rs274();

  std::vector<Outcome> outcomes;
  outcomes.reserve(paths.size());
  for (const fs::path& path : paths)
    outcomes.push_back(read_one(path));

  // rs274 on the accepted programs, a few threads at a time.
  std::vector<Outcome*> to_compare;
  for (Outcome& outcome : outcomes)
    if (rs274 && outcome.accepted && outcome.failures.empty() && outcome.bytes <= kMaxOracleBytes)
      to_compare.push_back(&outcome);
  const std::size_t threads = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 8);
  std::vector<std::future<void>> workers;
  std::atomic<std::size_t> next{0};
  for (std::size_t t = 0; t < threads; ++t)
    workers.push_back(std::async(std::launch::async, [&] {
      for (std::size_t i = next++; i < to_compare.size(); i = next++)
        compare_with_rs274(*to_compare[i], *rs274);
    }));
  for (auto& worker : workers)
    worker.get();

  std::size_t accepted = 0, compared = 0, matched = 0, expected_differences = 0;
  std::map<std::string, std::size_t> by_class;
  std::map<std::string, std::map<std::string, std::size_t>> words_by_class;
  for (const Outcome& outcome : outcomes) {
    for (const std::string& failure : outcome.failures)
      ADD_FAILURE() << outcome.name << ": " << failure;
    if (!outcome.accepted) {
      ++by_class[outcome.refusal_class];
      ++words_by_class[outcome.refusal_class][word_key(outcome.refusal_word)];
      continue;
    }
    ++accepted;
    if (!outcome.compared)
      continue;
    ++compared;
    const auto expected = kExpectedDifferences.find(outcome.name);
    if (outcome.difference.empty()) {
      ++matched;
      EXPECT_EQ(expected, kExpectedDifferences.end())
          << outcome.name << " is listed as an expected difference but agrees with rs274";
    } else if (expected != kExpectedDifferences.end()) {
      ++expected_differences;
    } else {
      ADD_FAILURE() << outcome.name << " differs from rs274: " << outcome.difference;
    }
  }
  for (const auto& listed : kExpectedDifferences) {
    const bool found = std::any_of(outcomes.begin(), outcomes.end(), [&](const Outcome& o) {
      return o.name == listed.first && o.compared;
    });
    EXPECT_TRUE(found) << listed.first
                       << " is listed as an expected difference but was not compared";
  }

  std::ostringstream summary;
  summary << "LinuxCNC example programs: " << outcomes.size() << " files, " << accepted
          << " accepted, " << compared << " of them run by rs274 and compared, " << matched
          << " agree move by move, " << expected_differences << " expected differences; "
          << outcomes.size() - accepted << " refused:\n";
  for (const auto& [name, count] : by_class) {
    summary << "  " << count << "  " << name << ":";
    for (const auto& [word, n] : words_by_class[name])
      summary << " " << word << (n > 1 ? " x" + std::to_string(n) : "");
    summary << "\n";
  }
  std::cout << summary.str();
  RecordProperty("files", static_cast<int>(outcomes.size()));
  RecordProperty("accepted", static_cast<int>(accepted));
  RecordProperty("compared_with_rs274", static_cast<int>(compared));
  RecordProperty("matched_rs274", static_cast<int>(matched));
  RecordProperty("refused", static_cast<int>(outcomes.size() - accepted));
  for (const auto& [name, count] : by_class)
    RecordProperty("refused: " + name, static_cast<int>(count));

  // The package ships mill programs read_gcode must read, and rs274 agrees
  // with us on them.
  EXPECT_GE(accepted, 8u);
  if (rs274) {
    EXPECT_GE(matched, 8u);
  }
}

// ---------------------------------------------------------------------------
// Programs written by others, kept in the repository (gcode/others/README.md).

fs::path others_dir() {
  return fs::path(ROBOMILL_SOURCE_DIR) / "tests/toolpath/gcode/others";
}

Program read_other(const std::string& name) {
  robomill::io::GcodeOptions options;
  options.source_name = name;
  return robomill::io::read_gcode(read_text(others_dir() / name), options);
}

InputError refusal_of(const std::string& name) {
  try {
    read_other(name);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << name << " was read, not refused";
  return InputError("", 0, "");
}

/// rs274 on `text` against read_gcode's moves: empty when they agree (or
/// rs274 is not installed, with a message), else the first difference.
std::string rs274_difference(const std::string& name, const std::string& text) {
  const std::optional<std::string> rs274 = find_rs274();
  if (!rs274) {
    std::cout << "rs274 is not installed: " << name << " is not compared with it\n";
    return {};
  }
  const OracleRun oracle = run_rs274(*rs274, text, fs::path(name).stem().string());
  if (oracle.status != 0)
    return "rs274 refused it:\n" + oracle.output;
  return first_difference(robomill::io::read_gcode(text, oracle_options(name)), oracle.moves);
}

struct Box {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d high = Eigen::Vector3d::Constant(-1e9);
};

/// The box the tip sweeps (arcs sampled finely), from the first move's end
/// on: the first move starts at the program origin, where the post never put
/// the tool.
Box swept_box(const Program& program, bool feed_only) {
  Box box;
  for (std::size_t n = 0; n < program.moves.size(); ++n) {
    const Move& move = program.moves[n];
    if (feed_only && move.kind != MotionKind::linear && move.kind != MotionKind::arc)
      continue;
    for (int k = n == 0 ? 256 : 0; k <= 256; ++k) {
      const Eigen::Vector3d p = robomill::toolpath::position_at(move, k / 256.0);
      box.low = box.low.cwiseMin(p);
      box.high = box.high.cwiseMax(p);
    }
  }
  return box;
}

double feed_length_m(const Program& program, double z_m) {
  double length = 0.0;
  for (const Move& move : program.moves)
    if ((move.kind == MotionKind::linear || move.kind == MotionKind::arc) &&
        std::abs(move.start_m.z() - z_m) < 1e-9 && std::abs(move.end_m.z() - z_m) < 1e-9)
      length += robomill::toolpath::path_length_m(move);
  return length;
}

std::size_t count_kind(const Program& program, MotionKind kind) {
  return static_cast<std::size_t>(std::count_if(program.moves.begin(), program.moves.end(),
                                                [&](const Move& m) { return m.kind == kind; }));
}

constexpr double kMm = 1e-3;
constexpr double kPerMinute = 1.0 / 60.0;

// FreeCAD linuxcnc_post, mm: a 5 mm end mill round a 3 x 3 mm square.
TEST(GcodeOthers, FreeCadLinuxCncPostMetric) {
  const Program p = read_other("freecad_linuxcnc_metric.ngc");
  // Rapids: Z9, Y-2.5, Z7, Z9 at the end (the repeated G0 Z9 and G0 X0 Y0
  // move nothing); the plunge; four G1 sides and four G2 corners.
  ASSERT_EQ(p.moves.size(), 13u);
  EXPECT_EQ(count_kind(p, MotionKind::rapid), 4u);
  EXPECT_EQ(count_kind(p, MotionKind::arc), 4u);
  EXPECT_EQ(p.moves[3].feed_m_s, 340.2 * kMm * kPerMinute);  // the plunge
  for (std::size_t n = 4; n < 12; ++n) {
    EXPECT_EQ(p.moves[n].feed_m_s, 140.4 * kMm * kPerMinute) << n;
    EXPECT_EQ(p.moves[n].tool, 1);
    EXPECT_NEAR(p.moves[n].spindle_rad_s, 123.0 * 2.0 * std::numbers::pi / 60.0, 1e-12);
  }
  // The square's sides (3 mm) and quarter circles of the tool radius 2.5 mm,
  // clockwise (climb milling outside): 12 + 5π mm at Z -1.
  EXPECT_NEAR(feed_length_m(p, -1.0 * kMm), (12.0 + 5.0 * std::numbers::pi) * kMm, 1e-12);
  for (std::size_t n = 4; n < 12; n += 2)
    EXPECT_NEAR(p.moves[n].sweep_rad * p.moves[n].normal.z(), -std::numbers::pi / 2, 1e-12);
  const Box box = swept_box(p, true);
  EXPECT_LE((box.low - Eigen::Vector3d(-2.5, -2.5, -1.0) * kMm).norm(), 1e-12);
  EXPECT_LE((box.high - Eigen::Vector3d(5.5, 5.5, 7.0) * kMm).norm(), 1e-12);
  ASSERT_EQ(p.tool_calls.size(), 1u);
  EXPECT_EQ(p.tool_calls[0].tool, 1);
  EXPECT_EQ(p.tool_calls[0].line, 13);
  const std::string difference = rs274_difference(
      "freecad_linuxcnc_metric.ngc", read_text(others_dir() / "freecad_linuxcnc_metric.ngc"));
  EXPECT_TRUE(difference.empty()) << difference;
}

// The same job posted in inches (4 decimals): the same path to the inch
// post's rounding (0.00005 in), feeds in in/min.
TEST(GcodeOthers, FreeCadLinuxCncPostInchIsTheMetricJob) {
  const Program inch = read_other("freecad_linuxcnc_inch.ngc");
  const Program metric = read_other("freecad_linuxcnc_metric.ngc");
  ASSERT_EQ(inch.moves.size(), metric.moves.size());
  const double rounding_m = 0.00005 * kMetresPerInch;
  for (std::size_t n = 0; n < inch.moves.size(); ++n) {
    const Move& a = inch.moves[n];
    const Move& b = metric.moves[n];
    EXPECT_EQ(a.kind, b.kind) << n;
    EXPECT_LE((a.end_m - b.end_m).lpNorm<Eigen::Infinity>(), rounding_m) << n;
    EXPECT_LE((a.centre_m - b.centre_m).lpNorm<Eigen::Infinity>(), rounding_m) << n;
    // 140.4 mm/min is 5.5276 in/min to the post's 4 decimals.
    EXPECT_NEAR(a.feed_m_s, b.feed_m_s, 0.00005 * kMetresPerInch * kPerMinute) << n;
  }
  EXPECT_EQ(inch.moves[5].feed_m_s, 5.5276 * kMetresPerInch * kPerMinute);
  const std::string difference = rs274_difference(
      "freecad_linuxcnc_inch.ngc", read_text(others_dir() / "freecad_linuxcnc_inch.ngc"));
  EXPECT_TRUE(difference.empty()) << difference;
}

// FreeCAD grbl_post (our geometry in its forms, README): the tool change is
// a comment, so no tool is named; every G17 arc carries K0.000.
TEST(GcodeOthers, FreeCadGrblPostProfile) {
  const Program p = read_other("freecad_grbl_profile.nc");
  // Rapids Z5, X-3 Y0, Z3; two plunges; 2 x 8 contour moves; the rapid up.
  ASSERT_EQ(p.moves.size(), 22u);
  EXPECT_EQ(count_kind(p, MotionKind::rapid), 4u);
  EXPECT_EQ(count_kind(p, MotionKind::arc), 8u);
  EXPECT_TRUE(p.tool_calls.empty());
  for (const Move& move : p.moves) {
    EXPECT_EQ(move.tool, 0);
    EXPECT_NEAR(move.spindle_rad_s, 12000.0 * 2.0 * std::numbers::pi / 60.0, 1e-9);
  }
  // 2 x (50 + 30) mm of sides and four quarter circles of 3 mm a pass.
  for (const double z : {-1.5, -3.0})
    EXPECT_NEAR(feed_length_m(p, z * kMm), (160.0 + 6.0 * std::numbers::pi) * kMm, 1e-12) << z;
  EXPECT_EQ(p.moves[4].feed_m_s, 600.0 * kMm * kPerMinute);
  const Box box = swept_box(p, true);
  EXPECT_LE((box.low - Eigen::Vector3d(-3.0, -3.0, -3.0) * kMm).norm(), 1e-12);
  EXPECT_LE((box.high - Eigen::Vector3d(53.0, 33.0, 3.0) * kMm).norm(), 1e-12);
  // rs274 refuses a K word in G17; without the K0.000 words (which move
  // nothing) it must agree move by move.
  std::string text = read_text(others_dir() / "freecad_grbl_profile.nc");
  for (std::size_t at = text.find(" K0.000"); at != std::string::npos; at = text.find(" K0.000"))
    text.erase(at, 7);
  const std::string difference = rs274_difference("freecad_grbl_profile.nc", text);
  EXPECT_TRUE(difference.empty()) << difference;
}

// LinuxCNC's "Circle Diamond Square" (NIST, 1994), inch. Its header: 4 x 4 x
// 2 in stock, top at Z 2, "cutter does not descend more than 0.94 in below
// top". (The header's "Y -0.250 to 3.915, Z 1.406 to 3.0" is the pocket part
// only: the ramps at the end go to Y 4.0 and, line 261, down to Z 1.06379.)
TEST(GcodeOthers, LinuxCncCircleDiamondSquare) {
  const Program p = read_other("linuxcnc_cds.ngc");
  ASSERT_FALSE(p.moves.empty());
  const Box box = swept_box(p, false);
  const double tolerance = 1e-9;
  EXPECT_NEAR(box.low.x(), 0.0, tolerance);
  EXPECT_NEAR(box.high.x(), 4.0 * kMetresPerInch, tolerance);
  EXPECT_NEAR(box.low.y(), -0.250 * kMetresPerInch, tolerance);
  EXPECT_NEAR(box.high.y(), 4.0 * kMetresPerInch, tolerance);
  EXPECT_NEAR(box.low.z(), 1.06379 * kMetresPerInch, tolerance);
  EXPECT_GE(box.low.z(), (2.0 - 0.94) * kMetresPerInch);
  EXPECT_NEAR(box.high.z(), 3.0 * kMetresPerInch, tolerance);
  const auto deepest =
      std::min_element(p.moves.begin(), p.moves.end(),
                       [](const Move& a, const Move& b) { return a.end_m.z() < b.end_m.z(); });
  EXPECT_EQ(deepest->line, 261);
  for (const Move& move : p.moves)
    if (move.kind != MotionKind::rapid) {
      EXPECT_NEAR(move.feed_m_s, 16.0 * kMetresPerInch * kPerMinute, 1e-15) << move.line;
      EXPECT_NEAR(move.spindle_rad_s, 3500.0 * 2.0 * std::numbers::pi / 60.0, 1e-9);
    }
  const std::string difference =
      rs274_difference("linuxcnc_cds.ngc", read_text(others_dir() / "linuxcnc_cds.ngc"));
  EXPECT_TRUE(difference.empty()) << difference;
}

// A LinuxCNC user's test: two tools, each a full circle G2 I-45 at 1 mm
// depth round (-70, 100); G43 without H takes the tool in the spindle.
TEST(GcodeOthers, LinuxCncTwoToolsFullCircles) {
  const Program p = read_other("linuxcnc_hk_ba20_testmill.ngc");
  // Per tool: (rapids Z10, Y100, X-25 for the first; Z10 for the second, the
  // tool being there already) the plunge, the circle, the rapid up; X-300 last.
  ASSERT_EQ(p.moves.size(), 11u);
  ASSERT_EQ(count_kind(p, MotionKind::arc), 2u);
  const std::array<std::pair<int, double>, 2> tools{{{13, 3000.0}, {18, 5000.0}}};
  std::size_t circle = 0;
  for (const Move& move : p.moves) {
    if (move.kind != MotionKind::arc)
      continue;
    EXPECT_EQ(move.tool, tools.at(circle).first);
    EXPECT_NEAR(move.spindle_rad_s, tools.at(circle).second * 2.0 * std::numbers::pi / 60.0, 1e-9);
    EXPECT_EQ(move.feed_m_s, 500.0 * kMm * kPerMinute);
    EXPECT_LE((move.centre_m - Eigen::Vector3d(-70.0, 100.0, -1.0) * kMm).norm(), 1e-12);
    EXPECT_NEAR(move.sweep_rad * move.normal.z(), -2.0 * std::numbers::pi, 1e-12);
    EXPECT_NEAR(robomill::toolpath::path_length_m(move), 2.0 * std::numbers::pi * 45.0 * kMm,
                1e-12);
    ++circle;
  }
  const Box box = swept_box(p, true);
  EXPECT_NEAR(box.low.x(), -115.0 * kMm, 1e-9);
  EXPECT_NEAR(box.high.y(), 145.0 * kMm, 1e-9);
  ASSERT_EQ(p.tool_calls.size(), 2u);
  EXPECT_EQ(p.tool_calls[1].tool, 18);
  // M6 stops the spindle: the rapid down after the second tool change (line
  // 32) runs before S5000 M3 (lines 38-39), as rs274 has it.
  EXPECT_EQ(p.moves[6].line, 32);
  EXPECT_EQ(p.moves[6].spindle_rad_s, 0.0);
  const std::string difference = rs274_difference(
      "linuxcnc_hk_ba20_testmill.ngc", read_text(others_dir() / "linuxcnc_hk_ba20_testmill.ngc"));
  EXPECT_TRUE(difference.empty()) << difference;
}

// The control stops the spindle for a tool change; M3 in the M6 block (or
// after it) turns it again.
TEST(GcodeOthers, AToolChangeStopsTheSpindle) {
  robomill::io::GcodeOptions options;
  const Program p = robomill::io::read_gcode(
      "G21 G90\nT1 M6\nS1000 M3\nG0 Z5\nT2 M6\nG0 X1\nM3\nG0 X2\nT3 M6 M4\nG0 X3\n", options);
  ASSERT_EQ(p.moves.size(), 4u);
  const double w = 1000.0 * 2.0 * std::numbers::pi / 60.0;
  EXPECT_NEAR(p.moves[0].spindle_rad_s, w, 1e-12);
  EXPECT_EQ(p.moves[1].spindle_rad_s, 0.0);  // after T2 M6, before M3
  EXPECT_NEAR(p.moves[2].spindle_rad_s, w, 1e-12);
  EXPECT_NEAR(p.moves[3].spindle_rad_s, -w, 1e-12);  // M4 in the M6 block
}

// Refused, rightly, by line and word.
TEST(GcodeOthers, CutterCompensationAndMissingFeedAreRefused) {
  // The two circles again, with G41: the path is not the tool centre.
  InputError e = refusal_of("linuxcnc_gmoccapy_cutter_comp.ngc");
  EXPECT_EQ(e.line(), 37);
  EXPECT_NE(std::string(e.what()).find("G41: cutter compensation is not modelled"),
            std::string::npos)
      << e.what();
  // FreeCAD's centroid_post: the cut reads, but the postamble's M25
  // (Centroid's own code: Z up to the tool-change height; M99 follows) is no
  // ISO or LinuxCNC word, and an M code read wrongly could move the tool.
  e = refusal_of("freecad_centroid_metric.ngc");
  EXPECT_EQ(e.line(), 36);
  EXPECT_NE(std::string(e.what()).find("M25: unknown M code"), std::string::npos) << e.what();
  // FreeCAD's oldest linuxcnc_post test output: G1 with no F anywhere.
  e = refusal_of("freecad_linuxcnc_no_feed.ngc");
  EXPECT_EQ(e.line(), 17);
  EXPECT_NE(std::string(e.what()).find("without a feed rate"), std::string::npos) << e.what();
}

}  // namespace

}  // namespace test_gcode_real_programs_cpp
