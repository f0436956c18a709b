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

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <future>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <typeinfo>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "toolpath/rs274_oracle.hpp"

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

}  // namespace
