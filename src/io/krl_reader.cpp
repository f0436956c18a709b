// KUKA KRL reader: a .src program and its .dat into a toolpath::Program in SI.
//
// Length (issue #32): this file cannot be split without harm. It is one
// interpreter: class KrlReader's members (values, declarations, the .dat,
// motions, CIRC, system variables, BAS, control flow) share one state machine
// (declared positions, arrays, INT/REAL variables, FDATs, base, tool, current
// frame, loop and block tables), and the statement splitting and frame
// helpers above it serve only it. A second file would need the whole class
// in a header of its own, for no reader of it but this one.
//
// Conventions, with what supports them:
//  * A frame {X, Y, Z, A, B, C} is the TCP in the base in force: X Y Z in mm,
//    A B C in degrees, rotation = Rz(A)·Ry(B)·Rx(C) (KUKA's Z-Y'-X'' angles,
//    KSS system-variables manual, FRAME). The tool works along +X of the TCP
//    frame by default ($TOOL_DIRECTION #X); KrlOptions::tool_direction picks
//    'x' or 'z'; the tool axis tip → spindle is minus that axis. So the usual
//    milling pose A 0, B 90, C 0 with #X points the tool down −Z: axis +Z.
//  * Positions after $BASE=BASE_DATA[n], BAS(#BASE,n) or an FDAT's BASE_NO are
//    in base n: mapped with KrlOptions::bases[n] (identity with a note when
//    absent). RoboDK's inline `$BASE = {FRAME: X ...}` is read in mm / deg.
//  * KUKA's inline forms (;FOLD LIN P1 Vel=0.2 m/s CPDAT1 Tool[1] Base[1]) are
//    comments; the statements inside the fold run: FDAT_ACT=FP1 names the
//    FDAT whose TOOL_NO and BASE_NO BAS(#CP_PARAMS, v) / BAS(#PTP_PARAMS, v)
//    activate, and BAS(#CP_PARAMS, v) sets the path speed v (m/s).
//  * A target that omits components keeps the current ones (in the current
//    base). After a PTP to an axis position (E6AXIS, HOME) the tip is unknown:
//    the next Cartesian target ends an air move (rapid) from the last known
//    point, with a note.
//  * CIRC aux, end runs on the circle through the three points; CA (circular
//    angle, degrees) sets the sweep from the start: positive in the sense
//    start → aux → end, negative against it; the end point then only fixes
//    the circle.
//  * FOR loops with an integer counter (STEP a constant) are unrolled, and so
//    are WHILE ... ENDWHILE and REPEAT ... UNTIL, and IF ... [ELSE] ENDIF is
//    taken, when the condition compares INT values (I <= N, I == 3 ...): the
//    usual way a program walks a FRAME array (P[I] in the .dat) is one of
//    these. A condition on inputs, BOOL or REAL values (WHILE $IN[1], IF
//    DONE) is refused, as are LOOP, SWITCH, GOTO, EXIT and subroutine calls.
//    Every unrolled statement counts against max_executed_statements, so a
//    loop that never ends is an error, not a hang.
//  * REAL variables given a literal value (DECL REAL FEED=0.04) may stand for
//    the speed in $VEL.CP = FEED; frame components (P[I].Z = ...) are not
//    assigned: REAL arithmetic is not modelled.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "krl_rotation.hpp"
#include "program_text.hpp"
#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/arc.hpp"

namespace robomill::io {
namespace {

namespace pt = program_text;
using Eigen::Vector3d;
using toolpath::MotionKind;
using toolpath::Move;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr long long kIntegerLimit = 1'000'000'000;  // loop bounds and indices beyond are typos

// ---------------------------------------------------------------------------
// Statements: one per line, comments and string contents removed, upper case.

struct Statement {
  int line = 0;
  std::string text;
};

// Removes the `;` comment (outside strings) and the contents of strings (an
// FDAT's POINT2[] " " may hold anything), folds to upper case, trims.
std::string clean_line(std::string_view raw) {
  std::string text;
  bool in_string = false;
  for (char c : raw) {
    if (c == '"') {
      in_string = !in_string;
      text += c;
      continue;
    }
    if (in_string)
      continue;
    if (c == ';')
      break;
    text += pt::is_blank(c) ? ' ' : pt::upper(c);
  }
  return std::string(pt::trim(text));
}

std::vector<Statement> split_statements(std::string_view text) {
  std::vector<Statement> statements;
  int line = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string_view::npos)
      end = text.size();
    ++line;
    std::string cleaned = clean_line(text.substr(begin, end - begin));
    begin = end + 1;
    if (!cleaned.empty() && cleaned[0] != '&')  // &ACCESS, &REL, &PARAM, &COMMENT
      statements.push_back({line, std::move(cleaned)});
  }
  return statements;
}

bool is_identifier_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '$' || c == '#';
}

// The leading identifier of `text` ("LIN_REL {X 5}" → "LIN_REL").
std::string_view leading_word(std::string_view text) {
  std::size_t n = 0;
  while (n < text.size() && is_identifier_char(text[n]))
    ++n;
  return text.substr(0, n);
}

// The Cartesian aggregates {…} (any of X, Y, Z, A, B, C) of a cleaned
// statement before `offset` (the ordinal of a FrameSite; io/krl_frame_turn
// counts alike).
int frames_before(std::string_view text, std::size_t offset) {
  int count = 0;
  for (std::size_t open = text.find('{'); open < offset; open = text.find('{', open + 1)) {
    const std::size_t close = text.find('}', open);
    if (close == std::string_view::npos)
      break;
    bool cartesian = false;
    std::string_view body = text.substr(open + 1, close - open - 1);
    if (const std::size_t colon = body.find(':'); colon != std::string_view::npos)
      body = body.substr(colon + 1);  // the type name: E6POS:, FRAME:
    for (std::string_view piece : pt::split_top_level(body)) {
      const std::string_view name = leading_word(pt::trim(piece));
      cartesian = cartesian || (name.size() == 1 &&
                                std::string_view("XYZABC").find(name[0]) != std::string_view::npos);
    }
    count += cartesian ? 1 : 0;
  }
  return count;
}

// ---------------------------------------------------------------------------
// Positions.

enum Component { kX, kY, kZ, kA, kB, kC };
constexpr std::array<std::string_view, 6> kComponentNames = {"X", "Y", "Z", "A", "B", "C"};

/// What a KRL aggregate or declared position says: Cartesian components
/// (any subset) or an axis position (A1 ... A6), whose tip is unknown here.
struct Target {
  std::array<std::optional<double>, 6> cartesian;
  bool joint = false;
  bool assigned = true;                     // false: declared without a value
  std::optional<toolpath::FrameSite> site;  // a Cartesian aggregate: where it is written
};

using Frame6 = std::array<double, 6>;  // X Y Z (mm), A B C (deg)

// KUKA's A, B, C (deg): R = Rz(A) Ry(B) Rx(C).
using krl_rotation::rotation_abc;

Eigen::Isometry3d to_isometry(const Frame6& f) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation_abc(f[kA], f[kB], f[kC]);
  pose.translation() = kMillimetre * Vector3d(f[kX], f[kY], f[kZ]);
  return pose;
}

// Inverse of to_isometry: Z-Y'-X'' angles of a rotation (B in [−90°, 90°]).
Frame6 to_frame6(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d& r = pose.linear();
  const Vector3d t = pose.translation() / kMillimetre;
  const double b = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  double a = std::atan2(r(1, 0), r(0, 0));
  double c = std::atan2(r(2, 1), r(2, 2));
  if (std::hypot(r(0, 0), r(1, 0)) < 1e-12) {  // gimbal lock: put the whole turn in A
    a = std::atan2(-r(0, 1), r(1, 1));
    c = 0.0;
  }
  return {t.x(), t.y(), t.z(), a / kDegree, b / kDegree, c / kDegree};
}

struct FdatRecord {
  std::optional<int> tool_no;
  std::optional<int> base_no;
  bool external_tcp = false;  // IPO_FRAME #TCP: the robot carries the part
};

struct PositionArray {
  long long size = 0;
  std::map<long long, Target> elements;
};

struct Loop {
  std::string counter;
  long long last = 0;
  long long step = 1;
  std::size_t body = 0;  // index of the first statement of the body
};

/// INT comparison operators of a KRL condition, longest first so "<=" is not
/// read as "<".
constexpr std::array<std::string_view, 6> kComparisons = {"<=", ">=", "==", "<>", "<", ">"};

class KrlReader {
 public:
  explicit KrlReader(const KrlOptions& options) : options_(options) { program_.dialect = "krl"; }

  toolpath::Program read(std::string_view src);

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    throw InputError(in_dat_ ? options_.dat_name : options_.source_name, line, message);
  }
  void note(int line, const std::string& text) { program_.notes.push_back({line, text}); }
  void note_once(const std::string& key, int line, const std::string& text) {
    if (noted_.insert(key).second)
      note(line, text);
  }

  // Declarations and data.
  void read_dat(std::string_view dat);
  bool declaration(const Statement& s);
  bool assignment(const Statement& s);
  void declare(const Statement& s, std::string_view type, std::string_view rest);
  Target aggregate(const Statement& s, std::string_view text) const;
  FdatRecord fdat_aggregate(const Statement& s, std::string_view text) const;
  long long integer(const Statement& s, std::string_view expression) const;
  double number(const Statement& s, std::string_view text, std::string_view what) const;
  bool condition(const Statement& s, std::string_view word, std::string_view text) const;
  Target target(const Statement& s, std::string_view text, bool ptp) const;
  const Target* lookup(const Statement& s, std::string_view name, bool ptp) const;

  // The program.
  void run(const std::vector<Statement>& statements);
  void execute(const std::vector<Statement>& statements, std::size_t& pc);
  void for_loop(const Statement& s, std::string_view rest, std::size_t& pc);
  void end_for(const Statement& s, std::size_t& pc);
  bool block_control(const Statement& s, std::string_view word, std::string_view rest,
                     std::size_t& pc);
  void motion(const Statement& s, std::string_view word, std::string_view rest);
  void circ(const Statement& s, std::string_view rest, bool relative);
  void system_variable(const Statement& s);
  void bas(const Statement& s, std::string_view arguments);
  void wait(const Statement& s, std::string_view rest);
  void set_base(const Statement& s, const Eigen::Isometry3d& base);
  void set_base_number(const Statement& s, long long n);
  void set_tool_number(const Statement& s, long long n);

  Frame6 resolve(const Statement& s, const Target& t, std::string_view word) const;
  Vector3d tool_axis(const Frame6& f) const;
  Vector3d tool_x(const Frame6& f) const;
  Vector3d program_point(const Frame6& f) const {
    return base_ * (kMillimetre * Vector3d(f[kX], f[kY], f[kZ]));
  }
  void move_to(const Statement& s, MotionKind kind, const Frame6& f);
  void finish(Move& move, const Statement& s, const Frame6& f);

  const KrlOptions& options_;
  toolpath::Program program_;
  std::set<std::string> noted_;
  bool in_dat_ = false;

  std::map<std::string, Target, std::less<>> positions_;
  std::map<std::string, PositionArray, std::less<>> arrays_;
  std::map<std::string, long long, std::less<>> integers_;
  std::map<std::string, double, std::less<>> reals_;    // REAL variables with a literal value
  std::set<std::string, std::less<>> other_variables_;  // REAL, BOOL, ...: declared, not modelled
  std::map<std::string, FdatRecord, std::less<>> fdats_;
  std::optional<FdatRecord> fdat_act_;
  std::optional<toolpath::FrameSource> frame_source_;  // the target of the move being built

  Eigen::Isometry3d base_ = Eigen::Isometry3d::Identity();
  std::optional<Frame6> current_;     // the TCP frame in the base in force
  std::optional<Vector3d> position_;  // the tip in the program frame
  Vector3d position_axis_ = Vector3d::UnitZ();
  Vector3d position_x_ = Vector3d::UnitX();  // robomill's tool x there (tool_x)
  bool air_move_pending_ = false;            // a PTP to an axis position left the tip unknown
  int air_move_line_ = 0;
  double vel_cp_m_s_ = 0.0;
  bool vel_cp_set_ = false;
  int tool_ = 0;
  std::vector<Loop> loops_;
  std::map<std::size_t, std::size_t> loop_end_;  // FOR index → ENDFOR index
  // WHILE → ENDWHILE, IF → ENDIF, ELSE → ENDIF; ENDWHILE → WHILE, UNTIL →
  // REPEAT; IF → ELSE (statement indices, matched before the program runs).
  std::map<std::size_t, std::size_t> block_end_;
  std::map<std::size_t, std::size_t> block_start_;
  std::map<std::size_t, std::size_t> else_of_;
  std::size_t executed_ = 0;
  bool ended_ = false;
};

// ---------------------------------------------------------------------------
// Values.

double KrlReader::number(const Statement& s, std::string_view text, std::string_view what) const {
  const std::optional<double> value = pt::parse_number(text);
  if (!value)
    fail(s.line, std::string(what) + ": '" + pt::excerpt(pt::trim(text)) +
                     "' is not a number; robomill reads literal numbers here, not expressions");
  return *value;
}

// An integer expression: terms (literals or INT variables) joined by + and −.
long long KrlReader::integer(const Statement& s, std::string_view expression) const {
  expression = pt::trim(expression);
  long long total = 0;
  int sign = 1;
  std::size_t n = 0;
  bool expect_term = true;
  while (n < expression.size()) {
    const char c = expression[n];
    if (pt::is_blank(c)) {
      ++n;
      continue;
    }
    if (expect_term) {
      if (c == '-' || c == '+') {
        sign = (c == '-') ? -sign : sign;
        ++n;
        continue;
      }
      std::size_t end = n;
      while (end < expression.size() && is_identifier_char(expression[end]))
        ++end;
      const std::string_view term = expression.substr(n, end - n);
      long long value = 0;
      if (term.empty()) {
        fail(s.line, "'" + pt::excerpt(expression) +
                         "': only integers, INT variables, + and - are read in indices and loop "
                         "bounds");
      } else if (const std::optional<long long> literal = pt::parse_integer(term)) {
        value = *literal;
      } else if (const auto it = integers_.find(term); it != integers_.end()) {
        value = it->second;
      } else {
        fail(s.line, "'" + pt::excerpt(term) +
                         "' is not an integer or a declared INT variable with a value");
      }
      if (std::abs(value) > kIntegerLimit)
        fail(s.line, "'" + pt::excerpt(term) + "' is beyond ±1e9");
      total += sign * value;
      if (std::abs(total) > kIntegerLimit)
        fail(s.line, "'" + pt::excerpt(expression) + "' is beyond ±1e9");
      sign = 1;
      expect_term = false;
      n = end;
    } else {
      if (c != '+' && c != '-')
        fail(s.line,
             "'" + pt::excerpt(expression) + "': only + and - are read in integer expressions");
      sign = (c == '-') ? -1 : 1;
      expect_term = true;
      ++n;
    }
  }
  if (expect_term)
    fail(s.line, "'" + pt::excerpt(expression) + "' is not a complete integer expression");
  return total;
}

// The condition of WHILE, UNTIL or IF: one comparison of two integer
// expressions, optionally in parentheses ("I <= N", "(I+1 <> LAST)").
// Anything else (inputs, BOOL, REAL, AND / OR) decides at run time on the
// robot, so the path cannot be known here: refused with the statement.
bool KrlReader::condition(const Statement& s, std::string_view word, std::string_view text) const {
  text = pt::trim(text);
  const std::string written = std::string(word) + " " + pt::excerpt(text);
  auto refuse = [&](const std::string& why) {
    fail(s.line, written + ": control flow is not modelled for this condition (" + why +
                     "); robomill runs FOR loops and WHILE, REPEAT ... UNTIL and IF on "
                     "comparisons of INT values (I <= N); unroll the program in the robot "
                     "post-processor");
  };
  while (text.size() >= 2 && text.front() == '(' && text.back() == ')') {
    int depth = 0;  // strip only parentheses that enclose the whole condition
    bool encloses = true;
    for (std::size_t n = 0; n + 1 < text.size(); ++n) {
      depth += text[n] == '(' ? 1 : text[n] == ')' ? -1 : 0;
      if (depth == 0) {
        encloses = false;
        break;
      }
    }
    if (!encloses)
      break;
    text = pt::trim(text.substr(1, text.size() - 2));
  }
  std::size_t at = std::string_view::npos;
  std::string_view op;
  for (std::string_view candidate : kComparisons) {
    const std::size_t found = text.find(candidate);
    if (found != std::string_view::npos && found < at) {
      at = found;
      op = candidate;
    }
  }
  if (at == std::string_view::npos)
    refuse("no comparison of INT values");
  const std::string_view left = text.substr(0, at);
  const std::string_view right = text.substr(at + op.size());
  for (std::string_view joined : {" AND ", " OR ", " EXOR ", "NOT "})
    if (text.find(joined) != std::string_view::npos)
      refuse("AND, OR and NOT are not evaluated");
  long long a = 0, b = 0;
  try {
    a = integer(s, left);
    b = integer(s, right);
  } catch (const InputError&) {
    refuse("its operands are not INT values known before the program runs");
  }
  if (op == "<=")
    return a <= b;
  if (op == ">=")
    return a >= b;
  if (op == "==")
    return a == b;
  if (op == "<>")
    return a != b;
  return op == "<" ? a < b : a > b;
}

// {X 10, Y 20, Z 30, A 0, B 90, C 0, S 2, T 35, E1 0} or {E6AXIS: A1 0, ..., A6 0}.
Target KrlReader::aggregate(const Statement& s, std::string_view text) const {
  text = pt::trim(text);
  if (text.size() < 2 || text.front() != '{' || text.back() != '}')
    fail(s.line, "'" + pt::excerpt(text) + "' is not a KRL aggregate {X ..., Y ..., ...}");
  std::string_view body = text.substr(1, text.size() - 2);
  if (const std::size_t colon = body.find(':'); colon != std::string_view::npos)
    body = body.substr(colon + 1);  // the type name: E6POS:, FRAME:, POS:, AXIS:
  Target result;
  bool cartesian = false;
  for (std::string_view piece : pt::split_top_level(body)) {
    if (piece.empty())
      continue;
    const std::string_view name = leading_word(piece);
    if (name.empty() || name.size() == piece.size())
      fail(s.line, "'" + pt::excerpt(piece) + "' in an aggregate: write NAME value, e.g. X 10.5");
    const double value = number(s, piece.substr(name.size()), name);
    if (name.size() == 2 && name[0] == 'A' && name[1] >= '1' && name[1] <= '6') {
      result.joint = true;
      continue;
    }
    if (name == "S" || name == "T" ||
        (name.size() == 2 && name[0] == 'E' && name[1] >= '1' && name[1] <= '6'))
      continue;  // posture bits and external axes: no effect on the tip
    const auto it = std::find(kComponentNames.begin(), kComponentNames.end(), name);
    if (it == kComponentNames.end())
      fail(s.line, "'" + pt::excerpt(name) +
                       "' is not a frame component; positions have X Y Z A B C (S T E1..E6) or "
                       "A1..A6");
    result.cartesian[static_cast<std::size_t>(it - kComponentNames.begin())] = value;
    cartesian = true;
  }
  if (cartesian && result.joint)
    fail(s.line, "an aggregate mixes Cartesian (X ... C) and axis (A1 ... A6) components");
  const std::string_view whole = s.text;
  if (cartesian && text.data() >= whole.data() && text.data() < whole.data() + whole.size())
    result.site = toolpath::FrameSite{
        in_dat_, s.line,
        frames_before(whole, static_cast<std::size_t>(text.data() - whole.data()))};
  return result;
}

FdatRecord KrlReader::fdat_aggregate(const Statement& s, std::string_view text) const {
  FdatRecord record;
  text = pt::trim(text);
  if (text.size() < 2 || text.front() != '{' || text.back() != '}')
    return record;
  for (std::string_view piece : pt::split_top_level(text.substr(1, text.size() - 2))) {
    const std::string_view name = leading_word(piece);
    const std::string_view value = pt::trim(piece.substr(name.size()));
    if (name == "TOOL_NO" || name == "BASE_NO") {
      const long long n = integer(s, value);
      if (n < 0 || n > 1024)
        fail(s.line, std::string(name) + " " + pt::excerpt(value) + ": expected 0 ... 1024");
      (name == "TOOL_NO" ? record.tool_no : record.base_no) = static_cast<int>(n);
    } else if (name == "IPO_FRAME") {
      record.external_tcp = value == "#TCP";
    }
  }
  return record;
}

// ---------------------------------------------------------------------------
// Declarations: DECL [GLOBAL] TYPE NAME[=VALUE] or NAME[size], in .dat and .src.

bool KrlReader::declaration(const Statement& s) {
  std::string_view text = s.text;
  bool has_decl = false;
  for (std::string_view prefix : {"GLOBAL ", "DECL ", "GLOBAL ", "CONST "}) {
    if (pt::starts_with_word(text, pt::trim(prefix))) {
      has_decl = has_decl || pt::trim(prefix) == "DECL";
      text = pt::trim(text.substr(pt::trim(prefix).size()));
    }
  }
  const std::string_view type = leading_word(text);
  static const std::set<std::string, std::less<>> kBuiltin = {
      "INT", "REAL", "BOOL", "CHAR", "E6POS", "POS", "FRAME", "E6AXIS", "AXIS"};
  if (!has_decl && kBuiltin.count(type) == 0)
    return false;
  if (type.empty())
    fail(s.line, "DECL without a type");
  declare(s, type, pt::trim(text.substr(type.size())));
  return true;
}

void KrlReader::declare(const Statement& s, std::string_view type, std::string_view rest) {
  const bool is_position =
      type == "E6POS" || type == "POS" || type == "FRAME" || type == "E6AXIS" || type == "AXIS";
  // One initialised name, or a list of names without values.
  const std::size_t equals = rest.find('=');
  std::vector<std::string_view> names;
  std::string_view value;
  if (equals != std::string_view::npos) {
    names.push_back(pt::trim(rest.substr(0, equals)));
    value = pt::trim(rest.substr(equals + 1));
  } else {
    names = pt::split_top_level(rest);
  }
  for (std::string_view declared : names) {
    const std::string_view name = leading_word(declared);
    if (name.empty())
      fail(s.line, "DECL " + std::string(type) + ": no variable name");
    const std::string key(name);
    const std::string_view after = pt::trim(declared.substr(name.size()));
    if (!after.empty() && after.front() == '[') {  // an array
      if (after.back() != ']')
        fail(s.line, "DECL " + key + "[...: expected NAME[size]");
      if (is_position) {
        const std::string_view inside = after.substr(1, after.size() - 2);
        long long size = inside.empty() ? kIntegerLimit : integer(s, inside);
        if (size < 1 || size > kIntegerLimit)
          fail(s.line, "DECL " + key + "[" + pt::excerpt(inside) + "]: the size must be 1 ... 1e9");
        arrays_[key].size = size;
      } else {
        other_variables_.insert(key);
      }
      continue;
    }
    if (!after.empty())
      fail(s.line, "DECL " + std::string(type) + " " + pt::excerpt(declared) +
                       ": expected NAME, NAME[size] or NAME = value");
    if (is_position) {
      if (!value.empty())
        positions_[key] = aggregate(s, value);
      else
        positions_.emplace(key, Target{{}, false, false, std::nullopt});
    } else if (type == "INT") {
      integers_[key] = value.empty() ? 0 : integer(s, value);
    } else if (type == "FDAT") {
      fdats_[key] = fdat_aggregate(s, value);
    } else if (const std::optional<double> real = pt::parse_number(value); type == "REAL" && real) {
      reals_[key] = *real;  // a speed the program may name: $VEL.CP = FEED
    } else {
      other_variables_.insert(key);  // REAL, BOOL, PDAT, LDAT and the rest: no motion
    }
  }
}

// NAME = value, NAME[index] = value for declared positions and INT variables.
bool KrlReader::assignment(const Statement& s) {
  const std::string_view text = s.text;
  const std::string_view name = leading_word(text);
  if (name.empty() || name[0] == '$')
    return false;
  std::string_view rest = pt::trim(text.substr(name.size()));
  std::optional<long long> index;
  if (!rest.empty() && rest.front() == '[') {
    const std::size_t close = rest.find(']');
    if (close == std::string_view::npos)
      fail(s.line, std::string(name) + "[: no closing ]");
    index = integer(s, rest.substr(1, close - 1));
    rest = pt::trim(rest.substr(close + 1));
  }
  if (!rest.empty() && rest.front() == '.' &&
      (arrays_.count(name) != 0 || positions_.count(name) != 0))
    fail(s.line, std::string(name) + (index ? "[" + std::to_string(*index) + "]" : "") +
                     pt::excerpt(rest.substr(0, rest.find('='))) +
                     " = ...: assigning one component of a frame is not modelled (it is REAL "
                     "arithmetic); write the whole frames in the .dat");
  if (rest.empty() || rest.front() != '=' || (rest.size() > 1 && rest[1] == '='))
    return false;
  const std::string_view value = pt::trim(rest.substr(1));
  if (name == "PDAT_ACT" || name == "LDAT_ACT" || name == "FDAT_ACT") {
    if (name == "FDAT_ACT") {
      const auto it = fdats_.find(value);
      if (it != fdats_.end())
        fdat_act_ = it->second;
      else
        note_once("FDAT " + std::string(value), s.line,
                  "FDAT_ACT=" + pt::excerpt(value) +
                      ": no such FDAT in the .dat; the tool and base stay as they are");
    }
    return true;
  }
  if (const auto array = arrays_.find(name); array != arrays_.end()) {
    if (!index)
      fail(s.line, std::string(name) + " is an array; assign its elements, " + std::string(name) +
                       "[n] = {...}");
    if (*index < 1 || *index > array->second.size)
      fail(s.line, std::string(name) + "[" + std::to_string(*index) +
                       "]: the index is outside 1 ... " + std::to_string(array->second.size));
    array->second.elements[*index] = target(s, value, false);
    return true;
  }
  if (index)
    fail(s.line, std::string(name) + "[...] = : " + std::string(name) +
                     " is not a declared position array (DECL FRAME " + std::string(name) +
                     "[n] in the .dat)");
  if (const auto position = positions_.find(name); position != positions_.end()) {
    position->second = target(s, value, false);  // {X ...} or another position, P[I]
    return true;
  }
  if (const auto real = reals_.find(name); real != reals_.end()) {
    if (const std::optional<double> literal = pt::parse_number(value)) {
      real->second = *literal;
      return true;
    }
    reals_.erase(real);  // an expression: its value is not known from here on
    other_variables_.insert(std::string(name));
  }
  if (const auto variable = integers_.find(name); variable != integers_.end()) {
    variable->second = integer(s, value);
    return true;
  }
  if (other_variables_.count(name) != 0) {
    note_once("assign " + std::string(name), s.line,
              std::string(name) + " = ...: a variable with no effect on the path; ignored");
    return true;
  }
  if (fdats_.count(name) != 0)
    return true;
  fail(s.line, std::string(name) + " = ...: " + std::string(name) +
                   " is not declared; declare it in the .dat (DECL E6POS " + std::string(name) +
                   " = {...}) or the program");
}

void KrlReader::read_dat(std::string_view dat) {
  in_dat_ = true;
  bool inside = false;
  for (const Statement& s : split_statements(dat)) {
    if (pt::starts_with_word(s.text, "DEFDAT")) {
      inside = true;
      continue;
    }
    if (pt::starts_with_word(s.text, "ENDDAT"))
      break;
    if (!inside)
      fail(s.line, "'" + pt::excerpt(leading_word(s.text)) +
                       "' before DEFDAT; a .dat file starts with DEFDAT name");
    if (pt::starts_with_word(s.text, "EXT") || pt::starts_with_word(s.text, "EXTFCT") ||
        pt::starts_with_word(s.text, "IMPORT"))
      continue;  // declarations of external routines and data: no motion
    if (declaration(s) || assignment(s))
      continue;
    fail(s.line, "'" + pt::excerpt(leading_word(s.text)) +
                     "' is not read in a .dat file (DECL, array elements P[n] = {...})");
  }
  in_dat_ = false;
}

// ---------------------------------------------------------------------------
// Targets.

const Target* KrlReader::lookup(const Statement& s, std::string_view text, bool ptp) const {
  const std::string_view name = leading_word(text);
  const std::string_view rest = pt::trim(text.substr(name.size()));
  if (name.empty())
    fail(s.line, "'" + pt::excerpt(text) + "' is not a position: write {X ..., Y ...} or a name");
  if (!rest.empty()) {
    if (rest.front() != '[' || rest.back() != ']')
      fail(s.line, "'" + pt::excerpt(text) + "' is not a position: write NAME or NAME[index]");
    const auto array = arrays_.find(name);
    if (array == arrays_.end())
      fail(s.line, std::string(name) + "[...]: no position array " + std::string(name) +
                       " is declared (DECL FRAME " + std::string(name) + "[n] in the .dat)");
    const long long index = integer(s, rest.substr(1, rest.size() - 2));
    const auto element = array->second.elements.find(index);
    if (element == array->second.elements.end())
      fail(s.line, std::string(name) + "[" + std::to_string(index) +
                       "] has no value; assign it in the .dat (" + std::string(name) + "[" +
                       std::to_string(index) + "] = {X ..., Y ..., Z ...})");
    return &element->second;
  }
  if (const auto it = positions_.find(name); it != positions_.end()) {
    if (!it->second.assigned)
      fail(s.line, std::string(name) + " is declared but has no value; give it one in the .dat (" +
                       std::string(name) + " = {X ..., Y ..., Z ...})");
    return &it->second;
  }
  if (ptp && (name == "XHOME" || name == "HOME")) {
    static const Target kAxisPosition{{}, true, true, std::nullopt};
    return &kAxisPosition;  // $H_POS / XHOME live in $config.dat: an axis position
  }
  fail(s.line, std::string(name) +
                   " is not a declared position; declare it in the .dat (DECL "
                   "E6POS " +
                   std::string(name) + " = {X ..., Y ..., Z ...})");
}

Target KrlReader::target(const Statement& s, std::string_view text, bool ptp) const {
  text = pt::trim(text);
  if (!text.empty() && text.front() == '{')
    return aggregate(s, text);
  return *lookup(s, text, ptp);
}

Frame6 KrlReader::resolve(const Statement& s, const Target& t, std::string_view word) const {
  Frame6 frame{};
  for (std::size_t n = 0; n < 6; ++n) {
    if (t.cartesian[n])
      frame[n] = *t.cartesian[n];
    else if (current_)
      frame[n] = (*current_)[n];
    else
      fail(s.line, std::string(word) + ": the target has no " + std::string(kComponentNames[n]) +
                       " and the robot's pose is not known here (program start or after a PTP to "
                       "an axis position); give the full frame {X, Y, Z, A, B, C}");
  }
  for (std::size_t n = 0; n < 6; ++n)
    if (std::abs(frame[n]) > 1e9)
      fail(s.line, std::string(word) + ": " + std::string(kComponentNames[n]) + " is beyond 1e9");
  return frame;
}

Vector3d KrlReader::tool_axis(const Frame6& f) const {
  const Eigen::Matrix3d r = base_.linear() * rotation_abc(f[kA], f[kB], f[kC]);
  const Vector3d working = options_.tool_direction == 'z' ? r.col(2) : r.col(0);
  return -working.normalized();
}

// robomill's tool frame has z along the axis (tip → spindle); its x is the
// TCP frame's axis that stays normal to the tool, renamed so the frame stays
// right-handed: (x, y, z) = (Z, Y, −X) with #X, (X, −Y, −Z) with #Z. The
// usual A 0, B 90, C 0 with #X is then robomill's ψ = 0 (x along the base's
// +X, z up), and A turns the tool about its axis by A.
Vector3d KrlReader::tool_x(const Frame6& f) const {
  const Eigen::Matrix3d r = base_.linear() * rotation_abc(f[kA], f[kB], f[kC]);
  return (options_.tool_direction == 'z' ? r.col(0) : r.col(2)).normalized();
}

// Where a move's end frame is written, the orientation it ends at and the
// base its numbers are in.
std::optional<toolpath::FrameSource> source_of(const std::optional<toolpath::FrameSite>& site,
                                               const Target& t, const Frame6& frame,
                                               const Eigen::Isometry3d& base) {
  if (!site)
    return std::nullopt;
  toolpath::FrameSource source;
  source.site = *site;
  source.complete = t.cartesian[kA] && t.cartesian[kB] && t.cartesian[kC];
  source.abc_deg = {frame[kA], frame[kB], frame[kC]};
  source.position_complete = t.cartesian[kX] && t.cartesian[kY] && t.cartesian[kZ];
  source.base_rotation = base.linear();
  source.base_origin_m = base.translation();
  return source;
}

// ---------------------------------------------------------------------------
// Motion.

void KrlReader::finish(Move& move, const Statement& s, const Frame6& f) {
  move.line = s.line;
  move.tool = tool_;
  move.spindle_rad_s = 0.0;  // KRL rarely states it: the job's process.spindle fills in
  if (move.kind == MotionKind::linear || move.kind == MotionKind::arc) {
    move.feed_m_s = vel_cp_m_s_;
    if (!vel_cp_set_)
      note_once("no $VEL.CP", s.line, "a LIN / CIRC before any $VEL.CP: its feed is 0");
  }
  program_.moves.push_back(move);
  program_.frame_sources.push_back(frame_source_);
  frame_source_.reset();
  position_ = move.end_m;
  position_axis_ = move.axis_end;
  position_x_ = move.tool_x_end;
  current_ = f;
}

void KrlReader::move_to(const Statement& s, MotionKind kind, const Frame6& f) {
  const Vector3d end = program_point(f);
  const Vector3d axis = tool_axis(f);
  if (!position_) {
    note(s.line, "the program's first Cartesian point: no move before it is modelled");
    program_.first_frame = frame_source_;
    frame_source_.reset();
    position_ = end;
    position_axis_ = axis;
    position_x_ = tool_x(f);
    current_ = f;
    return;
  }
  if (air_move_pending_) {
    note(s.line, "the PTP to an axis position of line " + std::to_string(air_move_line_) +
                     " leaves the tip unknown: an air move from the last known point ends here");
    kind = MotionKind::rapid;
    air_move_pending_ = false;
  }
  Move move;
  move.kind = kind;
  move.start_m = *position_;
  move.end_m = end;
  move.axis_start = position_axis_;
  move.axis_end = axis;
  move.oriented = true;
  move.tool_x_start = position_x_;
  move.tool_x_end = tool_x(f);
  finish(move, s, f);
}

void KrlReader::motion(const Statement& s, std::string_view word, std::string_view rest) {
  // Strip the approximation word (C_DIS, C_VEL, C_ORI, C_PTP, C_SPL) and, for
  // _REL, the frame (#BASE, #TOOL).
  bool in_tool_frame = false;
  for (bool changed = true; changed;) {
    changed = false;
    const std::size_t last_blank = rest.find_last_of(" \t}");
    const std::string_view tail =
        last_blank == std::string_view::npos ? rest : rest.substr(last_blank + 1);
    if (tail == "C_DIS" || tail == "C_VEL" || tail == "C_ORI" || tail == "C_PTP" ||
        tail == "C_SPL" || tail == "#BASE" || tail == "#TOOL") {
      in_tool_frame = in_tool_frame || tail == "#TOOL";
      rest = pt::trim(rest.substr(0, rest.size() - tail.size()));
      changed = !rest.empty();
    }
  }
  const bool relative = word.size() > 4 && word.substr(word.size() - 4) == "_REL";
  const std::string_view base_word = relative ? word.substr(0, word.size() - 4) : word;
  if (base_word == "CIRC" || base_word == "SCIRC")
    return circ(s, rest, relative);
  const bool ptp = base_word == "PTP" || base_word == "SPTP";
  if (rest.empty())
    fail(s.line, std::string(word) + ": no target; write " + std::string(word) +
                     " {X ..., Y ..., Z ...} or " + std::string(word) + " P1");
  const Target t = target(s, rest, ptp);
  if (t.joint) {
    if (!ptp || relative)
      fail(s.line, std::string(word) +
                       " to an axis position (A1 ... A6): only PTP moves to "
                       "axis positions; write a Cartesian frame");
    note(s.line, "PTP to an axis position: the tip is unknown until the next Cartesian target");
    if (position_)
      air_move_pending_ = true;
    air_move_line_ = s.line;
    current_.reset();
    return;
  }
  Frame6 frame{};
  if (relative) {
    if (!current_)
      fail(s.line, std::string(word) +
                       ": a relative move needs a known pose; program an "
                       "absolute target first");
    for (std::size_t n = kA; n <= kC; ++n)
      if (t.cartesian[n] && *t.cartesian[n] != 0.0)
        fail(s.line, std::string(word) + " with " + std::string(kComponentNames[n]) +
                         ": relative orientation changes are not modelled; write the absolute "
                         "frame");
    frame = *current_;
    Vector3d offset(t.cartesian[kX].value_or(0.0), t.cartesian[kY].value_or(0.0),
                    t.cartesian[kZ].value_or(0.0));
    if (offset.cwiseAbs().maxCoeff() > 1e9)
      fail(s.line, std::string(word) + ": an offset beyond 1e9 mm");
    if (in_tool_frame)  // #TOOL: the offset is along the TCP frame's axes
      offset = rotation_abc(frame[kA], frame[kB], frame[kC]) * offset;
    frame[kX] += offset.x();
    frame[kY] += offset.y();
    frame[kZ] += offset.z();
  } else {
    frame = resolve(s, t, word);
  }
  frame_source_ = source_of(relative ? std::nullopt : t.site, t, frame, base_);
  move_to(s, ptp ? MotionKind::rapid : MotionKind::linear, frame);
}

void KrlReader::circ(const Statement& s, std::string_view rest, bool relative) {
  const std::vector<std::string_view> parts = pt::split_top_level(rest);
  if (parts.size() < 2 || parts.size() > 3)
    fail(s.line, "CIRC: expected an auxiliary point and an end point (CIRC aux, end[, CA angle])");
  std::optional<double> ca_deg;
  if (parts.size() == 3) {
    if (!pt::starts_with_word(parts[2], "CA"))
      fail(s.line, "CIRC: '" + pt::excerpt(parts[2]) + "' after the end point; expected CA angle");
    ca_deg = number(s, parts[2].substr(2), "CA");
    if (*ca_deg == 0.0 || std::abs(*ca_deg) > 3600.0)
      fail(s.line, "CIRC: CA must be non-zero and within ±3600°");
  }
  if (!position_ || !current_ || air_move_pending_)
    fail(s.line,
         "CIRC: the start point is not known (program start or after a PTP to an axis "
         "position); move to a Cartesian point first");
  Target aux_target = target(s, parts[0], false);
  Target end_target = target(s, parts[1], false);
  if (aux_target.joint || end_target.joint)
    fail(s.line, "CIRC to an axis position: the points of a CIRC are Cartesian frames");
  Frame6 aux{}, end{};
  if (relative) {
    aux = end = *current_;
    for (std::size_t n = kX; n <= kZ; ++n) {
      aux[n] += aux_target.cartesian[n].value_or(0.0);
      end[n] += end_target.cartesian[n].value_or(0.0);
    }
    for (std::size_t n = kA; n <= kC; ++n)
      if (aux_target.cartesian[n].value_or(0.0) != 0.0 ||
          end_target.cartesian[n].value_or(0.0) != 0.0)
        fail(s.line, "CIRC_REL with " + std::string(kComponentNames[n]) +
                         ": relative orientation changes are not modelled");
  } else {
    aux = resolve(s, aux_target, "CIRC");
    end = resolve(s, end_target, "CIRC");
  }
  const Vector3d start_m = *position_;
  const Vector3d via_m = program_point(aux);
  const Vector3d end_m = program_point(end);
  toolpath::ArcResult arc = toolpath::arc_through(start_m, via_m, end_m);
  if (arc.problem != toolpath::ArcProblem::none)
    fail(s.line, "CIRC: the start, auxiliary and end points " +
                     std::string(arc.problem == toolpath::ArcProblem::start_is_end
                                     ? "coincide (start = end)"
                                     : "are on one line") +
                     "; a CIRC needs three distinct points on a circle");
  Move move = arc.move;
  if (ca_deg) {
    // CA: the sweep from the start, in the start → aux → end sense when
    // positive; the programmed end only fixes the circle.
    const double sense = move.sweep_rad >= 0.0 ? 1.0 : -1.0;
    move.sweep_rad = sense * *ca_deg * kDegree;
    const Eigen::AngleAxisd turn(move.sweep_rad, move.normal);
    move.end_m = move.centre_m + turn * (start_m - move.centre_m);
    const Vector3d end_in_base = (base_.inverse() * move.end_m) / kMillimetre;
    end[kX] = end_in_base.x();
    end[kY] = end_in_base.y();
    end[kZ] = end_in_base.z();
  }
  move.axis_start = position_axis_;
  move.axis_end = tool_axis(end);
  move.oriented = true;
  move.tool_x_start = position_x_;
  move.tool_x_end = tool_x(end);
  frame_source_ =
      source_of(relative || ca_deg ? std::nullopt : end_target.site, end_target, end, base_);
  finish(move, s, end);
}

// ---------------------------------------------------------------------------
// Settings.

void KrlReader::set_base(const Statement&, const Eigen::Isometry3d& base) {
  if (current_) {  // keep the pose, re-expressed in the new base
    const Eigen::Isometry3d pose = base_ * to_isometry(*current_);
    current_ = to_frame6(base.inverse() * pose);
  }
  base_ = base;
}

void KrlReader::set_base_number(const Statement& s, long long n) {
  if (n < 0 || n > 1024)
    fail(s.line, "base number " + std::to_string(n) + ": expected 0 ... 1024");
  const auto it = options_.bases.find(static_cast<int>(n));
  if (n == 0 || it == options_.bases.end()) {
    if (n != 0)
      note_once("base " + std::to_string(n), s.line,
                "BASE_DATA[" + std::to_string(n) +
                    "] is not given in the job (toolpath.bases): taken as the identity");
    set_base(s, Eigen::Isometry3d::Identity());
    return;
  }
  set_base(s, it->second);
}

void KrlReader::set_tool_number(const Statement& s, long long n) {
  if (n < 0 || n > 1024)
    fail(s.line, "tool number " + std::to_string(n) + ": expected 0 ... 1024");
  if (tool_ != static_cast<int>(n)) {
    tool_ = static_cast<int>(n);
    program_.tool_calls.push_back({tool_, s.line, std::nullopt, std::nullopt});
  }
}

// $VEL.CP = 0.2, $BASE = BASE_DATA[1], $BASE = {FRAME: X ...}, $TOOL = ..., $OUT[n] = TRUE ...
void KrlReader::system_variable(const Statement& s) {
  const std::size_t equals = s.text.find('=');
  if (equals == std::string::npos)
    fail(s.line, "'" + pt::excerpt(s.text) + "': expected $VARIABLE = value");
  std::string variable;
  for (char c : s.text.substr(0, equals))
    if (!pt::is_blank(c))
      variable += c;
  const std::string_view value = pt::trim(std::string_view(s.text).substr(equals + 1));
  if (value.empty())
    fail(s.line, variable + " = : no value");
  auto index_of = [&](std::string_view text, std::string_view prefix) {
    // PREFIX[n] → n
    if (text.substr(0, prefix.size()) != prefix || text.size() < prefix.size() + 2 ||
        text[prefix.size()] != '[' || text.back() != ']')
      return std::optional<long long>();
    return std::optional<long long>(
        integer(s, text.substr(prefix.size() + 1, text.size() - prefix.size() - 2)));
  };
  if (variable == "$VEL.CP") {
    const auto named = reals_.find(value);
    const double v = named != reals_.end() ? named->second : number(s, value, "$VEL.CP");
    if (!(v > 0.0) || v > 100.0)
      fail(s.line,
           "$VEL.CP: the path speed must be between 0 and 100 m/s, got " + pt::excerpt(value));
    vel_cp_m_s_ = v;
    vel_cp_set_ = true;
    return;
  }
  if (variable == "$BASE") {
    if (value.front() == '{') {
      const Target t = aggregate(s, value);
      if (t.joint)
        fail(s.line, "$BASE: a base is a frame {X, Y, Z, A, B, C}");
      Frame6 f{};
      for (std::size_t n = 0; n < 6; ++n)
        f[n] = t.cartesian[n].value_or(0.0);
      set_base(s, to_isometry(f));
      note_once("inline base", s.line, "$BASE = {FRAME: ...}: later positions are in this frame");
      return;
    }
    if (value == "$NULLFRAME")
      return set_base(s, Eigen::Isometry3d::Identity());
    if (const auto n = index_of(value, "BASE_DATA"))
      return set_base_number(s, *n);
    fail(s.line, "$BASE = " + pt::excerpt(value) +
                     ": expected BASE_DATA[n], $NULLFRAME or a frame {X ..., A ...}");
  }
  if (variable == "$TOOL") {
    if (const auto n = index_of(value, "TOOL_DATA"))
      return set_tool_number(s, *n);
    if (value.front() == '{' || value == "$NULLFRAME") {
      if (value.front() == '{')
        (void)aggregate(s, value);  // checked; the positions are the TCP's already
      note_once(
          "inline tool", s.line,
          "$TOOL = {FRAME: ...}: the programmed frames are the TCP's; the tool number stays " +
              std::to_string(tool_));
      return;
    }
    fail(s.line, "$TOOL = " + pt::excerpt(value) + ": expected TOOL_DATA[n] or a frame");
  }
  if (variable.substr(0, 5) == "$OUT[" || variable.substr(0, 7) == "$ANOUT[") {
    note_once(variable, s.line,
              variable + " = " + pt::excerpt(value) +
                  ": an output (often the spindle or coolant) is not modelled; the job's "
                  "process.spindle sets the spindle speed");
    return;
  }
  static const std::set<std::string, std::less<>> kSettings = {
      "$VEL.ORI1",  "$VEL.ORI2",  "$ACC.CP",   "$ACC.ORI1", "$ACC.ORI2",    "$APO.CDIS",
      "$APO.CPTP",  "$APO.CORI",  "$APO.CVEL", "$ADVANCE",  "$OV_PRO",      "$BWDSTART",
      "$ORI_TYPE",  "$CIRC_TYPE", "$VEL_AXIS", "$ACC_AXIS", "$CP_VEL_TYPE", "$SPL_ORI_JOINT_AUTO",
      "$GEAR_JERK", "$ACC"};
  std::string_view stem = variable;
  if (const std::size_t bracket = stem.find('['); bracket != std::string_view::npos)
    stem = stem.substr(0, bracket);
  if (kSettings.count(stem) != 0 || stem.substr(0, 4) == "$ACC" || stem.substr(0, 4) == "$VEL" ||
      stem.substr(0, 4) == "$APO")
    return;  // motion settings with no effect on the programmed path
  if (stem == "$TOOL_DIRECTION" || stem == "$IPO_MODE")
    fail(s.line, std::string(stem) +
                     ": changing how frames are read inside the program is not "
                     "modelled; set toolpath.tool_direction in the job");
  note_once(std::string(stem), s.line,
            std::string(stem) + " = ...: a system variable with no modelled effect; ignored");
}

// BAS(#INITMOV,0), BAS(#TOOL,n), BAS(#BASE,n), BAS(#CP_PARAMS,v), BAS(#PTP_PARAMS,v), ...
void KrlReader::bas(const Statement& s, std::string_view arguments) {
  const std::vector<std::string_view> args = pt::split_top_level(arguments);
  const std::string_view action = args[0];
  auto argument = [&](std::string_view what) {
    if (args.size() < 2)
      fail(s.line, "BAS(" + pt::excerpt(action) + ", ...): no " + std::string(what));
    return args[1];
  };
  auto apply_fdat = [&] {
    if (!fdat_act_)
      return;
    if (fdat_act_->external_tcp)
      fail(s.line,
           "IPO_FRAME #TCP: an external TCP (the robot carries the part) is not "
           "modelled");
    if (fdat_act_->tool_no)
      set_tool_number(s, *fdat_act_->tool_no);
    if (fdat_act_->base_no)
      set_base_number(s, *fdat_act_->base_no);
  };
  if (action == "#TOOL")
    return set_tool_number(s, integer(s, argument("tool number")));
  if (action == "#BASE")
    return set_base_number(s, integer(s, argument("base number")));
  if (action == "#CP_PARAMS" || action == "#VEL_CP") {
    const double v = number(s, argument("speed"), "BAS(#CP_PARAMS)");
    if (!(v > 0.0) || v > 100.0)
      fail(s.line,
           "BAS(" + std::string(action) + "): the path speed must be between 0 and 100 m/s");
    vel_cp_m_s_ = v;
    vel_cp_set_ = true;
    if (action == "#CP_PARAMS")
      apply_fdat();
    return;
  }
  if (action == "#PTP_PARAMS" || action == "#FRAMES" || action == "#CP_DAT" ||
      action == "#PTP_DAT") {
    if (action != "#CP_DAT" && action != "#PTP_DAT")
      apply_fdat();
    return;
  }
  note_once("BAS " + std::string(action), s.line,
            "BAS(" + pt::excerpt(action) + ", ...): no effect on the path; ignored");
}

void KrlReader::wait(const Statement& s, std::string_view rest) {
  if (pt::starts_with_word(rest, "SEC")) {
    const double t = number(s, rest.substr(3), "WAIT SEC");
    if (!(t >= 0.0) || t > 3600.0)
      fail(s.line, "WAIT SEC: the time must be between 0 and 3600 s");
    if (t == 0.0)
      return;  // WAIT SEC 0 only stops the advance run
    if (!position_) {
      note(s.line, "WAIT SEC before the first Cartesian point: ignored");
      return;
    }
    Move move;
    move.kind = MotionKind::dwell;
    move.start_m = move.end_m = *position_;
    move.axis_start = move.axis_end = position_axis_;
    move.oriented = true;
    move.tool_x_start = move.tool_x_end = position_x_;
    move.dwell_s = t;
    move.tool = tool_;
    move.line = s.line;
    program_.moves.push_back(move);
    program_.frame_sources.emplace_back();
    return;
  }
  if (pt::starts_with_word(rest, "FOR")) {
    note_once("WAIT FOR", s.line, "WAIT FOR ...: the condition is taken as met at once");
    return;
  }
  fail(s.line, "WAIT " + pt::excerpt(rest) + ": expected WAIT SEC t or WAIT FOR condition");
}

// ---------------------------------------------------------------------------
// The program: DEF ... END with FOR loops unrolled.

// FOR I = a TO b [STEP c]: sets the counter and enters the body, or jumps
// past ENDFOR when the loop is empty.
void KrlReader::for_loop(const Statement& s, std::string_view rest, std::size_t& pc) {
  // FOR I = a TO b [STEP c]
  const std::size_t equals = rest.find('=');
  const std::size_t to = rest.find(" TO ");
  if (equals == std::string_view::npos || to == std::string_view::npos || to < equals)
    fail(s.line, "FOR: expected FOR I = first TO last [STEP step]");
  const std::string counter(pt::trim(rest.substr(0, equals)));
  if (counter.empty() || leading_word(counter).size() != counter.size())
    fail(s.line, "FOR: the counter must be an INT variable name");
  std::string_view bounds = rest.substr(to + 4);
  long long step = 1;
  if (const std::size_t step_at = bounds.find(" STEP "); step_at != std::string_view::npos) {
    step = integer(s, bounds.substr(step_at + 6));
    bounds = bounds.substr(0, step_at);
  }
  if (step == 0)
    fail(s.line, "FOR: STEP 0 never ends");
  const long long first = integer(s, rest.substr(equals + 1, to - equals - 1));
  const long long last = integer(s, bounds);
  integers_[counter] = first;
  const std::size_t end = loop_end_.at(pc - 1);
  if ((step > 0 && first > last) || (step < 0 && first < last)) {
    pc = end + 1;  // an empty loop
    return;
  }
  loops_.push_back({counter, last, step, pc});
}

// ENDFOR: steps the counter and runs the body again until it passes the last value.
void KrlReader::end_for(const Statement& s, std::size_t& pc) {
  if (loops_.empty())
    fail(s.line, "ENDFOR without FOR");
  Loop& loop = loops_.back();
  long long& counter = integers_[loop.counter];
  counter += loop.step;
  if ((loop.step > 0 && counter <= loop.last) || (loop.step < 0 && counter >= loop.last)) {
    pc = loop.body;
    return;
  }
  loops_.pop_back();
}

// WHILE, ENDWHILE, REPEAT, UNTIL, IF, ELSE and ENDIF: jumps to the statement
// that runs next. False for any other statement.
bool KrlReader::block_control(const Statement& s, std::string_view word, std::string_view rest,
                              std::size_t& pc) {
  if (word == "WHILE") {
    if (!condition(s, word, rest))
      pc = block_end_.at(pc - 1) + 1;  // past ENDWHILE
    return true;
  }
  if (word == "ENDWHILE") {
    pc = block_start_.at(pc - 1);  // the WHILE again, which tests its condition
    return true;
  }
  if (word == "REPEAT" || word == "ENDIF")
    return true;
  if (word == "UNTIL") {
    if (!condition(s, word, rest))
      pc = block_start_.at(pc - 1) + 1;  // the body again
    return true;
  }
  if (word == "IF") {
    // IF condition THEN
    std::string_view test = rest;
    if (test.size() >= 5 && test.substr(test.size() - 5) == " THEN")
      test = test.substr(0, test.size() - 5);
    else if (test == "THEN" || test.empty())
      fail(s.line, "IF: no condition; expected IF condition THEN");
    else
      fail(s.line, "IF " + pt::excerpt(rest) + ": expected IF condition THEN");
    if (!condition(s, word, test)) {
      const auto else_at = else_of_.find(pc - 1);
      pc = (else_at != else_of_.end() ? else_at->second : block_end_.at(pc - 1)) + 1;
    }
    return true;
  }
  if (word == "ELSE") {
    pc = block_end_.at(pc - 1) + 1;  // the IF branch ran: skip the ELSE branch
    return true;
  }
  return false;
}

void KrlReader::execute(const std::vector<Statement>& statements, std::size_t& pc) {
  const Statement& s = statements[pc];
  const std::string_view text = s.text;
  const std::string_view word = leading_word(text);
  const std::string_view rest = pt::trim(text.substr(word.size()));
  if (++executed_ > options_.max_executed_statements)
    fail(s.line,
         "the program runs more than " + std::to_string(options_.max_executed_statements) +
             " statements once its loops are unrolled; check the loop bounds and that each WHILE "
             "or REPEAT loop changes its counter");
  ++pc;
  if (word == "END") {
    ended_ = true;
    return;
  }
  if (word == "DEF" || word == "DEFFCT" ||
      (word == "GLOBAL" &&
       (pt::starts_with_word(rest, "DEF") || pt::starts_with_word(rest, "DEFFCT"))))
    fail(s.line, std::string(word) +
                     " inside the program: local subroutines and functions are "
                     "not modelled; unroll the program in the robot "
                     "post-processor");
  if (word == "FOR")
    return for_loop(s, rest, pc);
  if (word == "ENDFOR")
    return end_for(s, pc);
  if (word == "INTERRUPT" || (word == "GLOBAL" && pt::starts_with_word(rest, "INTERRUPT"))) {
    // The INI fold's stop-message handler (INTERRUPT DECL 3 WHEN $STOPMESS ...):
    // it acts only when the robot faults.
    note_once("INTERRUPT", s.line, "INTERRUPT: interrupt handlers are not run");
    return;
  }
  if (block_control(s, word, rest, pc))
    return;
  if (word == "CONTINUE") {
    // Stops the advance run from halting at the next statement: timing on the
    // robot, no effect on the path.
    return;
  }
  static const std::set<std::string, std::less<>> kControlFlow = {
      "LOOP",      "ENDLOOP",    "SWITCH",           "CASE",   "DEFAULT", "ENDSWITCH",
      "GOTO",      "EXIT",       "RETURN",           "RESUME", "BRAKE",   "SPLINE",
      "ENDSPLINE", "PTP_SPLINE", "ON_ERROR_PROCEED", "ANIN",   "ANOUT"};
  if (kControlFlow.count(word) != 0)
    fail(s.line, std::string(word) +
                     ": control flow is not modelled; unroll the program in the "
                     "robot post-processor");
  if (word == "INI" || word == "HALT") {
    if (word == "HALT")
      note(s.line, "HALT: the program pauses here; the pause is not timed");
    return;
  }
  if (word == "BAS") {
    const std::size_t open = rest.find('(');
    const std::size_t close = rest.rfind(')');
    if (open != 0 || close == std::string_view::npos || close < open)
      fail(s.line, "BAS: expected BAS(#ACTION, value)");
    return bas(s, rest.substr(open + 1, close - open - 1));
  }
  if (word == "TRIGGER") {
    note_once("TRIGGER", s.line, "TRIGGER: path-related switching actions are not modelled");
    return;
  }
  static const std::set<std::string, std::less<>> kMotions = {
      "LIN",  "LIN_REL",  "PTP",  "PTP_REL",  "CIRC",  "CIRC_REL",
      "SLIN", "SLIN_REL", "SPTP", "SPTP_REL", "SCIRC", "SCIRC_REL"};
  if (kMotions.count(word) != 0)
    return motion(s, word, rest);
  if (word == "WAIT")
    return wait(s, rest);
  if (!word.empty() && word[0] == '$')
    return system_variable(s);
  if (declaration(s) || assignment(s))
    return;
  if (!word.empty() && !rest.empty() && rest.front() == '(')
    fail(s.line, std::string(word) +
                     "(...): subroutine calls are not modelled (control flow is "
                     "not modelled); unroll the program in the robot "
                     "post-processor");
  fail(s.line, "'" + pt::excerpt(word.empty() ? text : word) +
                   "' is not a KRL statement robomill reads (LIN, CIRC, PTP, $VEL.CP, $BASE, "
                   "FOR, ...)");
}

void KrlReader::run(const std::vector<Statement>& statements) {
  // The header: DEF name( ) after &-lines (already dropped).
  std::size_t pc = 0;
  if (statements.empty())
    fail(0, "the program is empty; a KRL program is DEF name( ) ... END");
  const std::string_view first = statements[0].text;
  const bool global = pt::starts_with_word(first, "GLOBAL");
  const std::string_view def = global ? pt::trim(first.substr(6)) : first;
  if (!pt::starts_with_word(def, "DEF"))
    fail(statements[0].line, "'" + pt::excerpt(leading_word(first)) +
                                 "' before DEF; a KRL program starts with DEF name( )");
  pc = 1;
  // Match FOR, WHILE, REPEAT and IF with their ends up front (the main program
  // ends at the first END), so a jump never has to search and a block that is
  // not closed is an error before anything runs.
  static const std::map<std::string_view, std::string_view> kCloser = {
      {"FOR", "ENDFOR"}, {"WHILE", "ENDWHILE"}, {"REPEAT", "UNTIL"}, {"IF", "ENDIF"}};
  std::vector<std::size_t> open;
  std::size_t main_end = statements.size();
  for (std::size_t n = pc; n < statements.size(); ++n) {
    const std::string_view word = leading_word(statements[n].text);
    if (word == "END") {
      main_end = n;
      break;
    }
    if (kCloser.count(word) != 0) {
      open.push_back(n);
      continue;
    }
    const bool is_else = word == "ELSE";
    const auto opener = std::find_if(kCloser.begin(), kCloser.end(), [&](const auto& pair) {
      return pair.second == word || (is_else && pair.first == "IF");
    });
    if (opener == kCloser.end())
      continue;
    const std::string expected(opener->first);
    if (open.empty() || leading_word(statements[open.back()].text) != expected)
      fail(statements[n].line,
           std::string(word) + " without " + expected +
               (open.empty() ? std::string()
                             : " (the " + std::string(leading_word(statements[open.back()].text)) +
                                   " of line " + std::to_string(statements[open.back()].line) +
                                   " is still open)"));
    const std::size_t start = open.back();
    if (is_else) {
      if (else_of_.count(start) != 0)
        fail(statements[n].line,
             "a second ELSE for the IF of line " + std::to_string(statements[start].line));
      else_of_[start] = n;
      continue;
    }
    open.pop_back();
    if (word == "ENDFOR")
      loop_end_[start] = n;
    block_end_[start] = n;
    block_start_[n] = start;
    if (const auto else_at = else_of_.find(start); else_at != else_of_.end())
      block_end_[else_at->second] = n;
  }
  if (!open.empty())
    fail(statements[open.back()].line,
         std::string(leading_word(statements[open.back()].text)) + " without " +
             std::string(kCloser.at(leading_word(statements[open.back()].text))));
  if (main_end == statements.size())
    fail(statements.back().line, "no END closes DEF; a KRL program ends with END");
  while (pc < statements.size() && !ended_)
    execute(statements, pc);
}

toolpath::Program KrlReader::read(std::string_view src) {
  if (src.size() > options_.max_bytes || options_.dat_text.size() > options_.max_bytes)
    throw InputError(src.size() > options_.max_bytes ? options_.source_name : options_.dat_name, 0,
                     "the KRL file is larger than the limit of " +
                         std::to_string(options_.max_bytes) +
                         " bytes; split the program or raise the limit");
  if (options_.tool_direction != 'x' && options_.tool_direction != 'z')
    throw InputError(options_.source_name, 0, "tool_direction must be 'x' (KUKA's default) or 'z'");
  program_.line_count = static_cast<std::size_t>(std::count(src.begin(), src.end(), '\n')) +
                        (!src.empty() && src.back() != '\n' ? 1 : 0);
  read_dat(options_.dat_text);
  run(split_statements(src));
  if (air_move_pending_)
    note(air_move_line_,
         "the program ends after a PTP to an axis position: that move is not "
         "modelled");
  return std::move(program_);
}

}  // namespace

toolpath::Program read_krl(std::string_view text, const KrlOptions& options) {
  return KrlReader(options).read(text);
}

}  // namespace robomill::io
