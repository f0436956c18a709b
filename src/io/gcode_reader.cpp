// ISO 6983 G-code reader: the programs CAM post-processors write for 3-axis
// mills, into one toolpath::Program in SI units (DESIGN.md §1, the toolpath
// stage).
//
// Length (issue #32): this file cannot be split without harm. It is one
// interpreter: class Interpreter's members (decode, modes, feed, spindle,
// moves, arcs, canned cycles, G28/G53) read and write one modal state (units,
// distance and feed modes, plane, motion mode, offsets, position, cycle
// state), and the lexer and G-code tables above it exist only for it and
// share its private types (Word, Block, Group, Motion). A second file would
// need that class and those types in a header of their own, for no reader
// of them but this interpreter.
//
// Dialect. There is no single G-code; we read the common core that Fanuc-,
// Haas-, Mastercam- and Fusion-style posts write, and where controls differ we
// follow LinuxCNC's rs274ngc interpreter, because it is the one freely
// available reference we can test against move by move
// (tests/toolpath/test_gcode_oracle.cpp runs it on tests/toolpath/gcode/):
//  * Start state: G17 G21 G90 G91.1 G94 G40 G49 G54, spindle off, tool 0, the
//    tool at the program-frame origin, no motion mode. A program that never
//    says G20 or G21 is read in millimetres, with a note.
//  * Arc centres I J K are incremental from the start point (G91.1) unless
//    G90.1 is in force; an omitted in-plane centre word is 0 (as rs274). A
//    centre word normal to the plane (K in G17) is ignored with a note, where
//    rs274 refuses it. G2/G3 with a centre but no axis word is a full circle
//    (rs274 and Fanuc alike). P on an arc is the number of turns.
//  * Arc radii must agree to 0.002 mm (0.0002 in in G20), rs274's tolerance,
//    or to 0.1 % of the radius (arc.cpp), else the arc is refused.
//  * Axis words without a motion G-code continue the modal motion (after G1,
//    `X10` is a G1 move; after G81, `X10 Y5` drills another hole). With no
//    motion mode in force (program start, after G80) they are refused, as
//    rs274 does. Unlike rs274, G80 may share a block with G0/G1 (the
//    `G0 G17 G40 G49 G80 G90` preamble of Fanuc-style posts): it is its own
//    group, as on Fanuc controls.
//  * Within a block the words act in rs274's order of execution (feed mode,
//    F, S, T, M6, M3/M4/M5, G4, plane, units, offsets, distance modes,
//    retract mode, G28/G30, motion, M0/M1/M2/M30). One exception: F is read
//    in the units in force after the block's G20/G21 (ISO: a block is in one
//    unit), where rs274 reads it in the previous unit. Feeds and speeds are
//    kept in SI, so a later G20/G21 does not rescale a modal F.
//  * G4 P and G82 P are seconds (rs274, Haas with a decimal point); an
//    integer P of 10 or more gets a note, since Fanuc reads it as ms.
//  * Drilling cycles G73 G81 G82 G83 in G17 expand into the moves rs274
//    prints: rapid up to R if below it, rapid in XY, rapid down to R, feed
//    down (G83: pecks of Q with rapid retracts to R and a rapid back down to
//    0.010 in above the last depth; G73: chip-breaking retracts of 0.010 in),
//    G82's dwell, rapid retract to the initial Z (G98) or R (G99), at each
//    hole while the cycle is modal, L times. With neither G98 nor G99 stated
//    we retract to the initial Z (G98, the Fanuc power-on default, the safe
//    side) with a note; rs274 defaults to G99.
//  * G28/G30 and G53: the machine's home is not in the program. The
//    intermediate point is a rapid; the retract home in Z is a rapid to
//    GcodeOptions::home_z_m when given, otherwise the tool stays where the
//    post left it (posts retract to clearance first) and a note says so.
//    Home X/Y are never modelled (note). G53 is accepted only with zero
//    coordinates (`G53 G0 Z0.`, machine home); other machine coordinates are
//    refused.
//  * G187 (Haas smoothing, P1-P3 and/or E tolerance) and G103 (Haas
//    look-ahead limit, P0-P15) are accepted with a note: they change how the
//    machine follows the path, not the path. rs274 refuses both.
//  * G15 G50 G50.1 G69, G92.1 G92.2 and G97 cancel modes that are refused
//    (polar, scaling, mirroring, rotation, G92 offsets, G96 constant surface
//    speed), so never in force: accepted as no-ops (G97 S is rpm, as S is
//    always read). G92.1 also clears G92 offsets a control kept from an earlier
//    program, which is what we assume anyway.
//  * M6 stops the spindle, as rs274 and the controls do: the moves after a
//    tool change and before the next M3/M4 have the spindle at rest (a
//    LinuxCNC user's program, tests/toolpath/gcode/others, rapids to the
//    next start before turning the spindle on).
//  * M2/M30 end the program; later lines are not read (note). `/` block
//    delete executes the block (a control with the switch off; rs274's
//    default), with a note.
//  * Refused with the line and word: G41/G42 cutter compensation, G93
//    inverse time, G92/G10/G68/G51 and other frame changes, LinuxCNC's polar
//    words (@ radius, ^ angle), subroutines (O sub/call, M98/M99, G65),
//    parameters and expressions (#1, [..]), rotary or extra axes (A B C U V
//    W), unknown letters (E but with G187) and G/M codes, a word repeated in
//    a block, two G codes of one modal group in a block, words no code in
//    the block uses (I J K R P Q L), feed moves with no F.
//  * Zero-length straight moves are dropped: they move nothing.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/arc.hpp"

namespace robomill::io {
namespace {

using toolpath::MotionKind;
using toolpath::Move;
using toolpath::Program;

constexpr double kMetresPerMm = 1e-3;
constexpr double kMetresPerInch = 25.4e-3;
constexpr double kRadPerSecondPerRpm = 2.0 * std::numbers::pi / 60.0;
// rs274's G83_RAPID_DELTA: how far above the last depth a peck cycle comes
// back down at rapid (0.010 in, in either unit).
constexpr double kPeckClearanceM = 0.010 * kMetresPerInch;
// Bounds that keep a few bytes from expanding into millions of moves.
constexpr int kMaxArcTurns = 10000;
constexpr std::size_t kMaxMovesPerBlock = 100000;

// ---------------------------------------------------------------- lexing --

/// One word of a block: a letter and its number, with the text as written
/// (upper case, without blanks) for messages.
struct Word {
  char letter = 0;
  double value = 0.0;
  std::string text;
};

struct Block {
  int line = 0;
  bool block_delete = false;
  std::vector<Word> words;
};

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

char upper(char c) {
  return static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
}

bool is_letter(char c) {
  return (c >= 'A' && c <= 'Z');
}

/// The line without comments and blanks, upper case. `( )` comments end at
/// the first `)`; `;` comments run to the end of the line.
std::string strip_line(std::string_view line, int number, const std::string& source,
                       bool& block_delete) {
  std::string compact;
  std::size_t i = 0;
  while (i < line.size() && is_blank(line[i]))
    ++i;
  if (i < line.size() && line[i] == '/') {
    block_delete = true;
    ++i;
  }
  for (; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '(') {
      const std::size_t close = line.find(')', i);
      if (close == std::string_view::npos)
        throw InputError(source, number,
                         "'(' opens a comment that the line does not close; "
                         "end the comment with ')'");
      i = close;
    } else if (c == ';') {
      break;
    } else if (!is_blank(c)) {
      compact += upper(c);
    }
  }
  return compact;
}

[[noreturn]] void refuse_parameters(const std::string& source, int line, std::string_view word) {
  throw InputError(source, line,
                   fmt::format("{}: parameters, variables and expressions (#, [ ]) are not "
                               "supported; post the program with plain numbers",
                               word));
}

/// Splits a comment-free, blank-free, upper-case line into words.
std::vector<Word> split_words(const std::string& compact, int number, const std::string& source) {
  std::vector<Word> words;
  std::size_t i = 0;
  while (i < compact.size()) {
    const char letter = compact[i];
    if (letter == '#' || letter == '[')
      refuse_parameters(source, number, compact.substr(i, 8));
    if (letter == '@' || letter == '^') {
      const std::size_t end = compact.find_first_not_of("+-0123456789.", i + 1);
      throw InputError(source, number,
                       fmt::format("{}: polar coordinates (LinuxCNC's @ radius and ^ angle) are "
                                   "not modelled; post the program in plain Cartesian "
                                   "coordinates (X Y)",
                                   compact.substr(i, end == std::string::npos ? end : end - i)));
    }
    if (!is_letter(letter))
      throw InputError(source, number,
                       fmt::format("'{}': unexpected character where a word (a letter and a "
                                   "number, e.g. X10.5) should begin",
                                   letter));
    std::size_t j = i + 1;
    const bool plus = j < compact.size() && compact[j] == '+';
    if (j < compact.size() && (compact[j] == '+' || compact[j] == '-'))
      ++j;
    const std::size_t digits = j;
    while (j < compact.size() &&
           (std::isdigit(static_cast<unsigned char>(compact[j])) || compact[j] == '.'))
      ++j;
    Word word{letter, 0.0, compact.substr(i, j - i)};
    if (j == digits) {
      if (j < compact.size() && (compact[j] == '#' || compact[j] == '['))
        refuse_parameters(source, number, compact.substr(i, j - i + 4));
      throw InputError(
          source, number,
          fmt::format("{}: a number must follow the letter (e.g. {}10.5)", word.text, letter));
    }
    const char* first = compact.data() + (plus ? i + 2 : i + 1);
    const char* last = compact.data() + j;
    const auto [end, error] = std::from_chars(first, last, word.value, std::chars_format::fixed);
    if (error != std::errc() || end != last || !std::isfinite(word.value))
      throw InputError(source, number, fmt::format("{}: not a number", word.text));
    words.push_back(std::move(word));
    i = j;
  }
  return words;
}

/// `O1234` (or Fanuc `:1234`) alone on a line names the program; anything
/// more after an O word is O-code control flow (sub, call, if, ...).
bool is_program_number(const std::string& compact, int number, const std::string& source) {
  if (compact.empty() || (compact[0] != 'O' && compact[0] != ':'))
    return false;
  const bool digits_only =
      compact.size() > 1 && std::all_of(compact.begin() + 1, compact.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) != 0;
      });
  if (digits_only)
    return true;
  throw InputError(source, number,
                   fmt::format("{}: subroutines and O-word control flow (sub, call, if, while, "
                               "repeat) are not supported; post the program flat, without "
                               "subprograms",
                               compact.substr(0, 16)));
}

// ------------------------------------------------------------- the codes --

/// Modal groups a block may set once each (rs274 / ISO 6983 grouping; G80
/// has its own group, see the dialect notes).
enum Group {
  kNonModal,  // G4 G28 G30 G53
  kMotion,    // G0 G1 G2 G3 G73 G81 G82 G83
  kCycleCancel,
  kPlane,
  kUnits,
  kDistance,
  kArcDistance,
  kFeedMode,
  kCutterComp,
  kToolLength,
  kWorkOffset,
  kPathControl,
  kRetract,
  kCancelOnly,  // G15 G50 G50.1 G69 G92.1 G92.2 G97: cancels of modes we never enter
  kSmoothing,   // G187 (Haas)
  kLookAhead,   // G103 (Haas)
  kGroupCount
};

/// A G code as tenths (G90.1 → 901), or nullopt when the value has more
/// than one decimal.
std::optional<int> code_tenths(double value) {
  const double tenths = std::round(value * 10.0);
  if (std::abs(value * 10.0 - tenths) > 1e-6 || tenths < 0.0 || tenths > 100000.0)
    return std::nullopt;
  return static_cast<int>(tenths);
}

/// The group of a G code; kGroupCount for codes we do not read.
Group g_group(int code) {
  switch (code) {
    case 40:
    case 280:
    case 300:
    case 530:
      return kNonModal;
    case 0:
    case 10:
    case 20:
    case 30:
    case 730:
    case 810:
    case 820:
    case 830:
      return kMotion;
    case 800:
      return kCycleCancel;
    case 170:
    case 180:
    case 190:
      return kPlane;
    case 200:
    case 210:
      return kUnits;
    case 900:
    case 910:
      return kDistance;
    case 901:
    case 911:
      return kArcDistance;
    case 940:
    case 950:
      return kFeedMode;
    case 400:
      return kCutterComp;
    case 430:
    case 490:
      return kToolLength;
    case 540:
    case 550:
    case 560:
    case 570:
    case 580:
    case 590:
    case 591:
    case 592:
    case 593:
      return kWorkOffset;
    case 610:
    case 611:
    case 640:
      return kPathControl;
    case 980:
    case 990:
      return kRetract;
    case 150:
    case 500:
    case 501:
    case 690:
    case 921:  // G92 offsets: refused, so never in force; a control that kept
    case 922:  // some from an earlier program drops them, as we assume
    case 970:  // G97: spindle speed in rpm (what S is read as); cancels G96,
               // constant surface speed, which is refused
      return kCancelOnly;
    case 1870:
      return kSmoothing;
    case 1030:
      return kLookAhead;
    default:
      return kGroupCount;
  }
}

/// Why a G code we know of is refused, or empty when it is unknown.
std::string g_refusal(int code) {
  switch (code) {
    case 410:
    case 420:
    case 411:
    case 421:
      return "cutter compensation is not modelled; post the program without compensation "
             "(G40) so that the path is the tool centre";
    case 930:
      return "inverse-time feed is not supported; post the program with G94 (units per "
             "minute)";
    case 650:
    case 660:
      return "macro calls are not supported; post the program flat, without macros";
    case 920:
    case 923:
    case 100:
    case 520:
      return "coordinate-system shifts are not modelled; post the program in one work "
             "offset (G54-G59)";
    case 680:
    case 681:
    case 682:
    case 160:
    case 510:
    case 511:
      return "rotated, scaled, mirrored or polar coordinates are not modelled; post the "
             "program in plain Cartesian coordinates";
    case 431:
    case 434:
    case 435:
      return "dynamic and 5-axis tool-length compensation are not modelled (3-axis G-code "
             "only)";
    case 840:
    case 850:
    case 860:
    case 870:
    case 880:
    case 890:
    case 740:
    case 760:
    case 330:
    case 331:
      return "this canned cycle (tapping, boring, threading) is not supported; only G73, G81, "
             "G82 and G83 are; post it as G81/G82 or as plain moves";
    default:
      return {};
  }
}

enum class Motion { none, rapid, linear, cw, ccw, g73, g81, g82, g83 };

bool is_cycle(Motion m) {
  return m == Motion::g73 || m == Motion::g81 || m == Motion::g82 || m == Motion::g83;
}

bool is_arc(Motion m) {
  return m == Motion::cw || m == Motion::ccw;
}

Motion motion_of(int code) {
  switch (code) {
    case 0:
      return Motion::rapid;
    case 10:
      return Motion::linear;
    case 20:
      return Motion::cw;
    case 30:
      return Motion::ccw;
    case 730:
      return Motion::g73;
    case 810:
      return Motion::g81;
    case 820:
      return Motion::g82;
    default:
      return Motion::g83;
  }
}

std::string_view motion_name(Motion m) {
  switch (m) {
    case Motion::rapid:
      return "G0";
    case Motion::linear:
      return "G1";
    case Motion::cw:
      return "G2";
    case Motion::ccw:
      return "G3";
    case Motion::g73:
      return "G73";
    case Motion::g81:
      return "G81";
    case Motion::g82:
      return "G82";
    case Motion::g83:
      return "G83";
    default:
      return "no motion";
  }
}

/// The words of one block sorted by role.
struct Decoded {
  int line = 0;
  std::array<const Word*, kGroupCount> g{};  // the G word of each group
  std::array<const Word*, 26> letter{};      // every other word but M, by letter
  const Word* m_stop = nullptr;              // M0 M1 M2 M30
  const Word* m_spindle = nullptr;           // M3 M4 M5
  const Word* m_tool_change = nullptr;       // M6

  const Word* operator[](char c) const { return letter[static_cast<std::size_t>(c - 'A')]; }
  bool has(char c) const { return (*this)[c] != nullptr; }
  bool has_axis() const { return has('X') || has('Y') || has('Z'); }
  int g_code(Group group) const { return g[group] ? *code_tenths(g[group]->value) : -1; }
};

// ----------------------------------------------------------- interpreter --

/// The selected plane: the indices of its first and second axes and of the
/// axis normal to it, and the normal about which G3 turns counter-clockwise
/// (G18 turns about +Y, from Z towards X, as rs274's XZ plane does).
struct Plane {
  int first, second, normal_axis;
  std::string_view name;
};

constexpr Plane kPlaneXY{0, 1, 2, "G17"};
constexpr Plane kPlaneZX{2, 0, 1, "G18"};
constexpr Plane kPlaneYZ{1, 2, 0, "G19"};

class Interpreter {
 public:
  explicit Interpreter(const GcodeOptions& options) : options_(options) {
    program_.dialect = "gcode";
  }

  /// Executes one block; false once the program has ended (M2/M30).
  bool execute(const Block& block);

  Program& program() { return program_; }
  void note(int line, std::string text) { program_.notes.push_back({line, std::move(text)}); }
  void note_once(const std::string& key, int line, std::string text) {
    if (noted_.insert(key).second)
      note(line, std::move(text));
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(options_.source_name, line_, message);
  }

  Decoded decode(const Block& block) const;
  void check_word_users(const Decoded& d, Motion motion, bool moves) const;

  void set_feed_mode(const Decoded& d);
  void set_feed(const Decoded& d);
  void set_spindle(const Decoded& d);
  void change_tool(const Decoded& d);
  void dwell(const Decoded& d);
  void set_modes(const Decoded& d);
  void go_home(const Decoded& d, int code);
  void machine_move(const Decoded& d);
  void move(const Decoded& d, Motion motion);
  void arc(const Decoded& d, bool clockwise, const Eigen::Vector3d& end);
  void drill(const Decoded& d, Motion cycle);

  double unit_m() const { return inches_ ? kMetresPerInch : kMetresPerMm; }
  std::string_view unit_name() const { return inches_ ? "in" : "mm"; }
  double to_units(double metres) const { return metres / unit_m(); }
  Eigen::Vector3d offset_m() const;
  Eigen::Vector3d target(const Decoded& d) const;
  double feed_m_s(Motion motion) const;
  double spindle_rad_s() const { return spindle_direction_ * spindle_rpm_ * kRadPerSecondPerRpm; }
  const Plane& plane() const { return *plane_; }

  void first_move_checks(const Decoded& d);
  void emit(Move move);
  void straight(MotionKind kind, const Eigen::Vector3d& end, double feed_m_s);

  const GcodeOptions& options_;
  Program program_;
  std::set<std::string> noted_;
  int line_ = 0;

  // Modal state.
  Motion motion_ = Motion::none;
  const Plane* plane_ = &kPlaneXY;
  bool inches_ = false;
  bool units_stated_ = false;
  bool incremental_ = false;
  bool incremental_centres_ = true;
  bool feed_per_rev_ = false;
  std::optional<double> feed_m_per_min_;  // G94 F, m/min
  std::optional<double> feed_m_per_rev_;  // G95 F, m/rev
  double spindle_rpm_ = 0.0;
  int spindle_direction_ = 0;  // +1 M3, −1 M4, 0 off
  std::optional<int> selected_tool_;
  int tool_ = 0;
  int work_offset_ = 1;  // G54 = 1 … G59 = 6, G59.1-3 = 7-9
  std::optional<bool> retract_to_r_;
  // Cycle words kept while a cycle is modal (SI, as programmed).
  double cycle_r_ = 0.0, cycle_z_ = 0.0, cycle_q_ = 0.0, cycle_p_ = 0.0;

  Eigen::Vector3d position_m_ = Eigen::Vector3d::Zero();
  bool moved_ = false;
  std::size_t block_moves_ = 0;
};

Decoded Interpreter::decode(const Block& block) const {
  Decoded d;
  d.line = block.line;
  const bool has_g187 = std::any_of(block.words.begin(), block.words.end(), [](const Word& w) {
    return w.letter == 'G' && code_tenths(w.value) == 1870;
  });
  for (const Word& word : block.words) {
    const char c = word.letter;
    if (c == 'G') {
      const std::optional<int> code = code_tenths(word.value);
      const Group group = code ? g_group(*code) : kGroupCount;
      if (group == kGroupCount) {
        const std::string why = code ? g_refusal(*code) : std::string();
        if (!why.empty())
          fail(fmt::format("{}: {}", word.text, why));
        fail(
            fmt::format("{}: unknown G code; robomill reads the G-code of 3-axis milling posts "
                        "(G0-G3, G4, G17-G21, G28, G40, G43, G49, G53-G59, G61, G64, G73, "
                        "G80-G83, G90, G91, G94, G95, G98, G99, G103, G187)",
                        word.text));
      }
      // The cancels of different refused modes (G50 G69 ...) may share a block.
      if (d.g[group] != nullptr && group != kCancelOnly)
        fail(fmt::format("{} and {} in one block: both set the same modal group; keep one",
                         d.g[group]->text, word.text));
      d.g[group] = &word;
    } else if (c == 'M') {
      const std::optional<int> code = code_tenths(word.value);
      const int m = code && *code % 10 == 0 ? *code / 10 : -1;
      const Word** slot = nullptr;
      switch (m) {
        case 0:
        case 1:
        case 2:
        case 30:
          slot = &d.m_stop;
          break;
        case 3:
        case 4:
        case 5:
          slot = &d.m_spindle;
          break;
        case 6:
          slot = &d.m_tool_change;
          break;
        case 7:
        case 8:
        case 9:
          continue;  // coolant: nothing robomill models
        case 98:
        case 99:
          fail(
              fmt::format("{}: subprogram calls are not supported; post the program flat, "
                          "without subprograms",
                          word.text));
        default:
          fail(
              fmt::format("{}: unknown M code; robomill reads M0 M1 M2 M3 M4 M5 M6 M7 M8 M9 "
                          "M30",
                          word.text));
      }
      if (*slot != nullptr)
        fail(fmt::format("{} and {} in one block: both belong to the same group; keep one",
                         (*slot)->text, word.text));
      *slot = &word;
    } else {
      switch (c) {
        case 'X':
        case 'Y':
        case 'Z':
        case 'I':
        case 'J':
        case 'K':
        case 'R':
        case 'F':
        case 'S':
        case 'T':
        case 'P':
        case 'Q':
        case 'L':
        case 'H':
        case 'D':
        case 'N':
          break;
        case 'E':
          if (has_g187)
            break;
          fail(
              fmt::format("{}: unknown word 'E'; robomill reads the letters F G H I J K L M N P "
                          "Q R S T X Y Z (and E with G187)",
                          word.text));
        case 'A':
        case 'B':
        case 'C':
        case 'U':
        case 'V':
        case 'W':
          fail(
              fmt::format("{}: rotary and extra axes are not modelled (3-axis G-code only); "
                          "post the program for a 3-axis machine (X Y Z)",
                          word.text));
        case 'O':
          fail(
              fmt::format("{}: an O word must stand alone at the start of a line (program "
                          "number); subroutines are not supported",
                          word.text));
        default:
          fail(
              fmt::format("{}: unknown word '{}'; robomill reads the letters F G H I J K L M "
                          "N P Q R S T X Y Z",
                          word.text, c));
      }
      const Word*& slot = d.letter[static_cast<std::size_t>(c - 'A')];
      if (slot != nullptr && c != 'N')
        fail(fmt::format("{} and {} in one block: a word may appear once", slot->text, word.text));
      slot = &word;
    }
  }
  if (d.g[kCycleCancel] && d.g[kMotion] && is_cycle(motion_of(d.g_code(kMotion))))
    fail(fmt::format("{} and {} in one block: G80 cancels the cycle that {} starts; keep one",
                     d.g[kCycleCancel]->text, d.g[kMotion]->text, d.g[kMotion]->text));
  return d;
}

/// rs274 refuses words that no code in the block uses; so do we, since a
/// stray R or P usually means a misread program.
void Interpreter::check_word_users(const Decoded& d, Motion motion, bool moves) const {
  const int nonmodal = d.g_code(kNonModal);
  const bool arc = moves && is_arc(motion);
  const bool cycle = moves && is_cycle(motion);
  const bool g64 = d.g_code(kPathControl) == 640;
  const bool g187 = d.g[kSmoothing] != nullptr;
  const bool g103 = d.g[kLookAhead] != nullptr;
  auto require = [&](char c, bool used, std::string_view users) {
    if (d.has(c) && !used)
      fail(fmt::format("{}: no code in this block uses {} (it belongs with {})", d[c]->text, c,
                       users));
  };
  require('I', arc, "G2/G3");
  require('J', arc, "G2/G3");
  require('K', arc, "G2/G3");
  require('R', arc || cycle, "G2/G3 or a drilling cycle");
  require('P', arc || nonmodal == 40 || g64 || g187 || g103 || (cycle && motion == Motion::g82),
          "G4, G82, G64, G187, G103 or G2/G3 turns");
  require('Q', g64 || (cycle && (motion == Motion::g73 || motion == Motion::g83)),
          "G73, G83 or G64");
  require('L', cycle, "a drilling cycle (repeats)");
  require('E', g187, "G187 (smoothing tolerance)");
  if ((g187 || g103) && d.has('P') &&
      ((g187 && g103) || arc || nonmodal == 40 || g64 || (cycle && motion == Motion::g82)))
    fail(
        fmt::format("{} with {}: another code of the block also reads P; put {} in a block "
                    "of its own",
                    (g187 ? d.g[kSmoothing] : d.g[kLookAhead])->text, d['P']->text,
                    (g187 ? d.g[kSmoothing] : d.g[kLookAhead])->text));
}

Eigen::Vector3d Interpreter::offset_m() const {
  const auto found = options_.work_offsets_m.find(work_offset_);
  return found == options_.work_offsets_m.end() ? Eigen::Vector3d::Zero() : found->second;
}

/// The end point the block's X Y Z words name (program frame, m).
Eigen::Vector3d Interpreter::target(const Decoded& d) const {
  Eigen::Vector3d end = position_m_;
  const Eigen::Vector3d offset = offset_m();
  constexpr std::array<char, 3> kAxes{'X', 'Y', 'Z'};
  for (int axis = 0; axis < 3; ++axis) {
    if (const Word* word = d[kAxes[static_cast<std::size_t>(axis)]]) {
      const double value_m = word->value * unit_m();
      end[axis] = incremental_ ? end[axis] + value_m : offset[axis] + value_m;
    }
  }
  return end;
}

double Interpreter::feed_m_s(Motion motion) const {
  if (feed_per_rev_) {
    if (!feed_m_per_rev_)
      fail(fmt::format("{} without a feed rate: no F since G95 (feed per revolution)",
                       motion_name(motion)));
    if (spindle_rpm_ <= 0.0)
      fail(fmt::format("{}: G95 feed per revolution needs a spindle speed; no S is programmed",
                       motion_name(motion)));
    return *feed_m_per_rev_ * spindle_rpm_ / 60.0;
  }
  if (!feed_m_per_min_)
    fail(fmt::format("{} without a feed rate: no F since the program start", motion_name(motion)));
  if (*feed_m_per_min_ <= 0.0)
    fail(fmt::format("{} with feed rate 0: program a positive F", motion_name(motion)));
  return *feed_m_per_min_ / 60.0;
}

void Interpreter::set_feed_mode(const Decoded& d) {
  const int code = d.g_code(kFeedMode);
  if (code == 940)
    feed_per_rev_ = false;
  else if (code == 950)
    feed_per_rev_ = true;
}

void Interpreter::set_feed(const Decoded& d) {
  const Word* f = d['F'];
  if (f == nullptr)
    return;
  if (f->value < 0.0)
    fail(fmt::format("{}: a feed rate cannot be negative", f->text));
  // F is read in the block's units (after its G20/G21): see the dialect notes.
  const int units = d.g_code(kUnits);
  const double unit = units == 200 ? kMetresPerInch : units == 210 ? kMetresPerMm : unit_m();
  if (feed_per_rev_)
    feed_m_per_rev_ = f->value * unit;
  else
    feed_m_per_min_ = f->value * unit;
}

void Interpreter::set_spindle(const Decoded& d) {
  if (const Word* s = d['S']) {
    if (s->value < 0.0)
      fail(
          fmt::format("{}: a spindle speed cannot be negative; turn the spindle with M4", s->text));
    spindle_rpm_ = s->value;
  }
}

void Interpreter::change_tool(const Decoded& d) {
  if (const Word* t = d['T']) {
    if (t->value < 0.0 || t->value != std::floor(t->value) || t->value > 1e9)
      fail(fmt::format("{}: a tool number is a whole number of 0 or more", t->text));
    selected_tool_ = static_cast<int>(t->value);
  }
  if (d.m_tool_change == nullptr)
    return;
  if (!selected_tool_)
    note(line_, "M6 with no T selected: the spindle holds no known tool (tool 0)");
  tool_ = selected_tool_.value_or(0);
  program_.tool_calls.push_back({tool_, line_, std::nullopt, std::nullopt});
  // The control stops the spindle to change the tool (rs274, Fanuc, Haas);
  // it turns again at the next M3/M4, which a block's own M3 after M6 is.
  spindle_direction_ = 0;
}

void Interpreter::dwell(const Decoded& d) {
  if (d.g_code(kNonModal) != 40)
    return;
  const Word* p = d['P'];
  if (p == nullptr)
    fail(d.has('X') ? "G4 X: a dwell in X is the Fanuc form; write G4 P<seconds>"
                    : "G4 without P: write the dwell time in seconds, G4 P0.5");
  if (p->value < 0.0)
    fail(fmt::format("{}: a dwell time cannot be negative", p->text));
  if (p->value >= 10.0 && p->text.find('.') == std::string::npos)
    note(line_, fmt::format("G4 {}: read as {} s (rs274); Fanuc controls read a P without a "
                            "decimal point as milliseconds",
                            p->text, p->value));
  Move move;
  move.kind = MotionKind::dwell;
  move.start_m = move.end_m = position_m_;
  move.dwell_s = p->value;
  emit(move);
}

void Interpreter::set_modes(const Decoded& d) {
  switch (d.g_code(kPlane)) {
    case 170:
      plane_ = &kPlaneXY;
      break;
    case 180:
      plane_ = &kPlaneZX;
      break;
    case 190:
      plane_ = &kPlaneYZ;
      break;
    default:
      break;
  }
  if (const int units = d.g_code(kUnits); units >= 0) {
    inches_ = units == 200;
    units_stated_ = true;
  }
  if (d.g_code(kToolLength) == 430)
    note_once("G43", line_,
              "G43: tool length compensation: the programmed point is the tool tip; the tool's "
              "length comes from the job");
  if (d.has('H') && d.g_code(kToolLength) != 430 && d.g_code(kToolLength) != 490)
    note_once("H", line_, fmt::format("{} without G43: ignored", d['H']->text));
  if (const int offset = d.g_code(kWorkOffset); offset >= 0) {
    static constexpr std::array<std::pair<int, int>, 9> kIndex{
        {{540, 1}, {550, 2}, {560, 3}, {570, 4}, {580, 5}, {590, 6}, {591, 7}, {592, 8}, {593, 9}}};
    for (const auto& [code, index] : kIndex)
      if (code == offset)
        work_offset_ = index;
    const bool given = options_.work_offsets_m.contains(work_offset_);
    if (!given && (work_offset_ != 1 || !options_.work_offsets_m.empty()))
      note_once(fmt::format("offset{}", work_offset_), line_,
                fmt::format("{}: work offset {} is not given (toolpath work offsets): taken as "
                            "zero, the same origin as G54",
                            d.g[kWorkOffset]->text, work_offset_));
  }
  if (const int distance = d.g_code(kDistance); distance >= 0)
    incremental_ = distance == 910;
  if (const int centres = d.g_code(kArcDistance); centres >= 0)
    incremental_centres_ = centres == 911;
  if (const int retract = d.g_code(kRetract); retract >= 0)
    retract_to_r_ = retract == 990;
  // Haas smoothing (G187 P1-P3 rough/medium/finish, E corner tolerance) and
  // look-ahead (G103 P0-P15) settings change how closely and how fast the
  // machine follows the path, not the programmed path: accepted, noted.
  if (const Word* g187 = d.g[kSmoothing]) {
    const Word* p = d['P'];
    if (p != nullptr && (p->value < 1.0 || p->value > 3.0 || p->value != std::floor(p->value)))
      fail(fmt::format("G187 {}: the smoothing level P is 1, 2 or 3", p->text));
    const Word* e = d['E'];
    if (e != nullptr && e->value <= 0.0)
      fail(fmt::format("G187 {}: the smoothing tolerance E must be positive", e->text));
    note_once("G187", line_,
              fmt::format("{}: machine smoothing (Haas); it changes how closely the machine "
                          "follows the path at speed, not the programmed path: ignored",
                          g187->text));
  }
  if (const Word* g103 = d.g[kLookAhead]) {
    const Word* p = d['P'];
    if (p != nullptr && (p->value < 0.0 || p->value > 15.0 || p->value != std::floor(p->value)))
      fail(fmt::format("G103 {}: the look-ahead limit P is a whole number from 0 to 15", p->text));
    note_once("G103", line_,
              fmt::format("{}: look-ahead limit (Haas); it changes how the machine plans its "
                          "speed, not the programmed path: ignored",
                          g103->text));
  }
}

void Interpreter::first_move_checks(const Decoded& d) {
  if (moved_)
    return;
  moved_ = true;
  if (!units_stated_)
    note(line_, "no G20 or G21 before the first move: millimetres assumed (G21)");
  std::string unset;
  for (char c : {'X', 'Y', 'Z'})
    if (!d.has(c) || incremental_)
      unset += c;
  if (!unset.empty())
    note(line_, fmt::format("the first move does not give {} absolutely: the tool is taken to "
                            "start at the program-frame origin",
                            unset));
}

void Interpreter::emit(Move move) {
  move.tool = tool_;
  move.line = line_;
  move.spindle_rad_s = spindle_rad_s();
  const bool finite = move.start_m.allFinite() && move.end_m.allFinite() &&
                      move.centre_m.allFinite() && std::isfinite(move.sweep_rad) &&
                      std::isfinite(move.feed_m_s);
  if (!finite)
    fail("the move's coordinates overflow; check the numbers on this line");
  if (++block_moves_ > kMaxMovesPerBlock)
    fail(fmt::format("this block expands into more than {} moves; check L, Q and P",
                     kMaxMovesPerBlock));
  position_m_ = move.end_m;
  program_.moves.push_back(std::move(move));
}

void Interpreter::straight(MotionKind kind, const Eigen::Vector3d& end, double feed_m_s) {
  if ((end - position_m_).norm() <= 1e-12)
    return;  // moves nothing
  Move move;
  move.kind = kind;
  move.start_m = position_m_;
  move.end_m = end;
  move.feed_m_s = kind == MotionKind::rapid ? 0.0 : feed_m_s;
  emit(move);
}

void Interpreter::move(const Decoded& d, Motion motion) {
  first_move_checks(d);
  const Eigen::Vector3d end = target(d);
  switch (motion) {
    case Motion::rapid:
      straight(MotionKind::rapid, end, 0.0);
      break;
    case Motion::linear:
      straight(MotionKind::linear, end, feed_m_s(motion));
      break;
    case Motion::cw:
    case Motion::ccw:
      arc(d, motion == Motion::cw, end);
      break;
    default:
      drill(d, motion);
      break;
  }
}

void Interpreter::arc(const Decoded& d, bool clockwise, const Eigen::Vector3d& end) {
  const std::string_view code = clockwise ? "G2" : "G3";
  const double feed = feed_m_s(clockwise ? Motion::cw : Motion::ccw);
  const Plane& p = plane();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal[p.normal_axis] = 1.0;
  constexpr std::array<char, 3> kCentreWords{'I', 'J', 'K'};
  const char first_word = kCentreWords[static_cast<std::size_t>(p.first)];
  const char second_word = kCentreWords[static_cast<std::size_t>(p.second)];
  const char normal_word = kCentreWords[static_cast<std::size_t>(p.normal_axis)];
  const bool has_centre = d.has(first_word) || d.has(second_word);
  if (d.has(normal_word))
    note(line_, fmt::format("{} in a {} arc: the centre word normal to the plane is ignored",
                            d[normal_word]->text, p.name));
  const Word* r = d['R'];
  if (r != nullptr && has_centre)
    fail(fmt::format("{} with {}{}: give either a radius or a centre, not both", code, r->text,
                     d.has(first_word) ? d[first_word]->text : d[second_word]->text));
  if (r == nullptr && !has_centre)
    fail(fmt::format("{} without {} {} or R: an arc needs its centre or its radius", code,
                     first_word, second_word));
  int extra_turns = 0;
  if (const Word* turns = d['P']) {
    if (turns->value < 1.0 || turns->value != std::floor(turns->value) ||
        turns->value > kMaxArcTurns)
      fail(fmt::format("{}: the number of turns P is a whole number from 1 to {}", turns->text,
                       kMaxArcTurns));
    if (r != nullptr)
      fail(fmt::format("{} with {}: turns need a centre (I J K), not a radius", turns->text,
                       r->text));
    extra_turns = static_cast<int>(turns->value) - 1;
  }
  const double tolerance_m = inches_ ? 0.0002 * kMetresPerInch : 0.002 * kMetresPerMm;
  toolpath::ArcResult result;
  std::string how;
  if (r != nullptr) {
    result = toolpath::arc_from_radius(position_m_, end, r->value * unit_m(), normal, clockwise,
                                       tolerance_m);
    how = r->text;
  } else {
    Eigen::Vector3d centre = position_m_;
    const Eigen::Vector3d offset = offset_m();
    for (const int axis : {p.first, p.second}) {
      const Word* word = d[kCentreWords[static_cast<std::size_t>(axis)]];
      const double value_m = word ? word->value * unit_m() : 0.0;
      centre[axis] = incremental_centres_ ? position_m_[axis] + value_m : offset[axis] + value_m;
    }
    result = toolpath::arc_from_centre(position_m_, end, centre, normal, clockwise, extra_turns,
                                       tolerance_m);
    how = incremental_centres_ ? "I J K (incremental, G91.1)" : "I J K (absolute, G90.1)";
  }
  switch (result.problem) {
    case toolpath::ArcProblem::none:
      break;
    case toolpath::ArcProblem::zero_radius:
      fail(fmt::format("{}: the centre from {} lies on the start or end point (radius 0)", code,
                       how));
    case toolpath::ArcProblem::start_is_end:
      fail(
          fmt::format("{} {}: the end point is the start point; an R arc cannot be a full "
                      "circle; give the centre with I J K",
                      code, how));
    case toolpath::ArcProblem::radius_mismatch:
    case toolpath::ArcProblem::collinear:
      if (r != nullptr)
        fail(
            fmt::format("{} {}: the end point is {:.6g} {} from the start, more than the "
                        "diameter; check R and the end point",
                        code, how, 2.0 * to_units(result.end_radius_m), unit_name()));
      fail(
          fmt::format("{}: the end point is not on the arc: radius {:.6g} {} at the start and "
                      "{:.6g} {} at the end (centre from {}); check the centre and the end "
                      "point",
                      code, to_units(result.start_radius_m), unit_name(),
                      to_units(result.end_radius_m), unit_name(), how));
  }
  Move move = result.move;
  move.feed_m_s = feed;
  emit(move);
}

void Interpreter::drill(const Decoded& d, Motion cycle) {
  const std::string_view code = motion_name(cycle);
  if (plane_ != &kPlaneXY)
    fail(fmt::format("{} in {}: drilling cycles are read in G17 only (the tool axis is Z)", code,
                     plane().name));
  const double feed = feed_m_s(cycle);
  const bool continuing = motion_ == cycle;
  auto modal_word = [&](char c, double& kept, double scale) {
    if (const Word* word = d[c])
      kept = word->value * scale;
    else if (!continuing)
      fail(fmt::format("{} without {}: the first block of a cycle needs {}", code, c, c));
  };
  modal_word('R', cycle_r_, unit_m());
  modal_word('Z', cycle_z_, unit_m());
  if (cycle == Motion::g73 || cycle == Motion::g83) {
    modal_word('Q', cycle_q_, unit_m());
    if (cycle_q_ <= 0.0)
      fail(fmt::format("{}: the peck depth Q must be positive", d.has('Q') ? d['Q']->text : code));
  }
  if (cycle == Motion::g82) {
    modal_word('P', cycle_p_, 1.0);
    if (cycle_p_ < 0.0)
      fail(fmt::format("{}: a dwell time cannot be negative", d['P']->text));
  }
  int repeats = 1;
  if (const Word* l = d['L']) {
    if (l->value < 1.0 || l->value != std::floor(l->value) ||
        l->value > static_cast<double>(kMaxMovesPerBlock))
      fail(fmt::format("{}: the number of repeats L is a whole number of 1 or more", l->text));
    repeats = static_cast<int>(l->value);
  }
  if (!retract_to_r_)
    note_once("retract", line_,
              fmt::format("{} with neither G98 nor G99 in force: retracting to the initial Z "
                          "(G98)",
                          code));

  // rs274's convert_cycle_xy: positions of the hole, R plane and bottom.
  const Eigen::Vector3d offset = offset_m();
  double old_z = position_m_.z();
  double x = position_m_.x(), y = position_m_.y(), r_z = 0.0, bottom_z = 0.0;
  double dx = 0.0, dy = 0.0;
  if (incremental_) {
    dx = d.has('X') ? d['X']->value * unit_m() : 0.0;
    dy = d.has('Y') ? d['Y']->value * unit_m() : 0.0;
    r_z = old_z + cycle_r_;
    bottom_z = r_z + cycle_z_;
  } else {
    if (d.has('X'))
      x = offset.x() + d['X']->value * unit_m();
    if (d.has('Y'))
      y = offset.y() + d['Y']->value * unit_m();
    r_z = offset.z() + cycle_r_;
    bottom_z = offset.z() + cycle_z_;
  }
  if (r_z < bottom_z)
    fail(fmt::format("{}: the R plane ({:.6g} {}) is below the hole bottom Z ({:.6g} {})", code,
                     to_units(r_z - offset.z()), unit_name(), to_units(bottom_z - offset.z()),
                     unit_name()));
  const double depth_m = r_z - bottom_z;
  const double q_m = cycle_q_;
  const bool pecks = cycle == Motion::g73 || cycle == Motion::g83;
  const double peck_count = pecks ? std::ceil(depth_m / q_m) : 1.0;
  if (static_cast<double>(repeats) * (3.0 * peck_count + 4.0) >
      static_cast<double>(kMaxMovesPerBlock))
    fail(
        fmt::format("{}: {} holes of {:.0f} pecks each are more moves than robomill reads from "
                    "one block; check Q and L",
                    code, repeats, peck_count));

  if (old_z < r_z) {
    straight(MotionKind::rapid, {position_m_.x(), position_m_.y(), r_z}, 0.0);
    old_z = r_z;
  }
  const double clear_z = retract_to_r_.value_or(false) ? r_z : old_z;
  for (int hole = 0; hole < repeats; ++hole) {
    x += dx;
    y += dy;
    straight(MotionKind::rapid, {x, y, old_z}, 0.0);
    straight(MotionKind::rapid, {x, y, r_z}, 0.0);
    if (pecks) {
      // Depths r − kQ above the bottom, each computed afresh (no drift).
      for (int k = 1;; ++k) {
        const double depth_z = r_z - k * q_m;
        if (depth_z <= bottom_z + 1e-12)
          break;
        straight(MotionKind::linear, {x, y, depth_z}, feed);
        if (cycle == Motion::g83)
          straight(MotionKind::rapid, {x, y, r_z}, 0.0);
        straight(MotionKind::rapid, {x, y, depth_z + kPeckClearanceM}, 0.0);
      }
    }
    straight(MotionKind::linear, {x, y, bottom_z}, feed);
    if (cycle == Motion::g82) {
      Move pause;
      pause.kind = MotionKind::dwell;
      pause.start_m = pause.end_m = position_m_;
      pause.dwell_s = cycle_p_;
      emit(pause);
    }
    straight(MotionKind::rapid, {x, y, clear_z}, 0.0);
    old_z = clear_z;
  }
}

void Interpreter::go_home(const Decoded& d, int code) {
  const std::string_view name = code == 280 ? "G28" : "G30";
  // The intermediate point, in the distance mode in force.
  if (d.has_axis())
    straight(MotionKind::rapid, target(d), 0.0);
  const bool z_home = d.has('Z') || !d.has_axis();
  const bool xy_home = d.has('X') || d.has('Y') || !d.has_axis();
  if (z_home) {
    if (options_.home_z_m) {
      straight(MotionKind::rapid, {position_m_.x(), position_m_.y(), *options_.home_z_m}, 0.0);
    } else {
      note(line_, fmt::format("{}: the machine's home Z is not known (toolpath home_z): the tool "
                              "is taken to stay at Z = {:.6g} {}, where the program left it",
                              name, to_units(position_m_.z() - offset_m().z()), unit_name()));
    }
  }
  if (xy_home)
    note(line_, fmt::format("{}: the return to the machine's home in X/Y is not modelled; the "
                            "next move starts where the tool was",
                            name));
}

void Interpreter::machine_move(const Decoded& d) {
  for (char c : {'X', 'Y', 'Z'}) {
    if (const Word* word = d[c]; word && word->value != 0.0)
      fail(
          fmt::format("G53 {}: machine coordinates are not known to robomill; only the home "
                      "retract (G53 G0 Z0, X0, Y0) is accepted",
                      word->text));
  }
  const int motion = d.g_code(kMotion);
  const Motion mode = motion >= 0 ? motion_of(motion) : motion_;
  if (mode != Motion::rapid && mode != Motion::linear)
    fail("G53 needs G0 or G1 in force");
  if (d.has('Z')) {
    if (options_.home_z_m) {
      straight(MotionKind::rapid, {position_m_.x(), position_m_.y(), *options_.home_z_m}, 0.0);
    } else {
      note(line_, fmt::format("G53 Z0: the machine's home Z is not known (toolpath home_z): the "
                              "tool is taken to stay at Z = {:.6g} {}, where the program left it",
                              to_units(position_m_.z() - offset_m().z()), unit_name()));
    }
  }
  if (d.has('X') || d.has('Y'))
    note(line_,
         "G53 X0/Y0: the machine's home in X/Y is not modelled; the next move starts "
         "where the tool was");
}

bool Interpreter::execute(const Block& block) {
  line_ = block.line;
  block_moves_ = 0;
  if (block.words.empty())
    return true;
  const Decoded d = decode(block);
  if (block.block_delete)
    note_once("/", line_,
              "'/' block delete: the block is executed, as on a control with the switch off");

  const int nonmodal = d.g_code(kNonModal);
  const int motion_code = d.g_code(kMotion);
  Motion motion = motion_code >= 0 ? motion_of(motion_code) : motion_;
  if (d.g[kCycleCancel] && motion_code < 0)
    motion = Motion::none;
  const bool homing = nonmodal == 280 || nonmodal == 300;
  const bool machine = nonmodal == 530;
  if (homing && motion_code >= 0)
    fail(fmt::format("{} and {} in one block: both use the axis words; keep one",
                     d.g[kNonModal]->text, d.g[kMotion]->text));
  // A motion happens when axis words are given (or an arc's centre alone:
  // a full circle), or when a cycle is named.
  const bool arc_centre_only =
      motion_code >= 0 && is_arc(motion) && (d.has('I') || d.has('J') || d.has('K') || d.has('R'));
  const bool moves = !homing && !machine &&
                     (d.has_axis() || arc_centre_only || (motion_code >= 0 && is_cycle(motion)));
  if (moves && motion == Motion::none) {
    const Word* axis = d.has('X') ? d['X'] : d.has('Y') ? d['Y'] : d['Z'];
    fail(
        fmt::format("{}: no motion mode is in force (there is none at the program start and "
                    "after G80); write G0 or G1 in the block",
                    axis->text));
  }
  check_word_users(d, motion, moves);

  set_feed_mode(d);
  set_feed(d);
  set_spindle(d);
  change_tool(d);
  if (d.m_spindle) {
    const int m = static_cast<int>(std::lround(d.m_spindle->value));
    spindle_direction_ = m == 3 ? 1 : m == 4 ? -1 : 0;
  }
  dwell(d);
  set_modes(d);
  if (homing)
    go_home(d, nonmodal);
  if (machine)
    machine_move(d);
  if (moves)
    move(d, motion);
  motion_ = motion;

  if (d.m_stop) {
    const int m = static_cast<int>(std::lround(d.m_stop->value));
    if (m == 2 || m == 30)
      return false;
    note_once(fmt::format("M{}", m), line_,
              fmt::format("{}: program stop; the analysis runs through it", d.m_stop->text));
  }
  return true;
}

/// Splits the text into lines at "\n", "\r\n" or a lone "\r".
std::vector<std::string_view> split_at_line_ends(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n' || text[i] == '\r') {
      lines.push_back(text.substr(start, i - start));
      if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n')
        ++i;
      start = i + 1;
    }
  }
  if (start < text.size())
    lines.push_back(text.substr(start));
  return lines;
}

bool is_percent_line(std::string_view line) {
  for (const char c : line) {
    if (c == '%')
      return true;
    if (!is_blank(c))
      return false;
  }
  return false;
}

}  // namespace

toolpath::Program read_gcode(std::string_view text, const GcodeOptions& options) {
  if (text.size() > options.max_bytes)
    throw InputError(options.source_name, 0,
                     fmt::format("the program is {} bytes, more than the limit of {} bytes; "
                                 "raise the limit (toolpath max_bytes) if it is really meant",
                                 text.size(), options.max_bytes));
  const std::vector<std::string_view> lines = split_at_line_ends(text);
  Interpreter interpreter(options);
  for (std::size_t index = 0; index < lines.size(); ++index) {
    const int number = static_cast<int>(index + 1);
    if (is_percent_line(lines[index]))
      continue;
    Block block;
    block.line = number;
    const std::string compact =
        strip_line(lines[index], number, options.source_name, block.block_delete);
    if (is_program_number(compact, number, options.source_name))
      continue;
    block.words = split_words(compact, number, options.source_name);
    if (interpreter.execute(block))
      continue;
    // M2/M30: the program ends here.
    for (std::size_t rest = index + 1; rest < lines.size(); ++rest) {
      if (!is_percent_line(lines[rest]) &&
          lines[rest].find_first_not_of(" \t\r\f\v") != std::string_view::npos) {
        interpreter.note(number, fmt::format("the program ends here; the lines after it (from "
                                             "line {}) are not read",
                                             rest + 1));
        break;
      }
    }
    break;
  }
  Program& program = interpreter.program();
  program.line_count = lines.size();
  return std::move(program);
}

}  // namespace robomill::io
