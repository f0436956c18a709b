// APT / CL data reader (ISO 4343-style cutter location source as NX, CATIA,
// Creo, Mastercam and Fusion posts write it) into a toolpath::Program in SI.
//
// Length (issue #32): this file cannot be split without harm. It is one
// interpreter: class AptReader's record handlers (UNITS, FEDRAT, SPINDL,
// CUTTER, LOADTL, CIRCLE, MSYS, CYCLE, DELAY, FROM, GOTO) all read and write
// one state machine (units, feed, spindle, tool, frame, pending circle, cycle,
// current point and axis), and the record splitting above it serves only it.
// A second file would need the class in a header of its own, for no reader
// of it but this one.
//
// Conventions, with what supports them:
//  * Records end at the line end; a `$` at the end of a line continues the
//    record on the next line; `$$` starts a comment (ISO 4343 aptsource).
//    PARTNO, PPRINT, REMARK, INSERT, TPRINT and NX's TOOL PATH carry free text.
//  * END ends a section (spindle off, as ISO 4343's END stops the machine);
//    FINI ends the program: records after it are not read.
//  * CIRCLE/xc,yc,zc,i,j,k,r[,...] is followed by the GOTO that ends the arc;
//    the arc runs from the current point counter-clockwise about (i,j,k) by
//    the right-hand rule (PTC Creo "CL Output for Circular Interpolation":
//    "the plane vector determines the plane and direction using the right hand
//    rule": 0,0,1 = CCW in XY, 0,0,-1 = CW; NX and CATIA write the same). The
//    centre's height only places the plane; a GOTO off the plane makes a helix
//    (Creo's helical example gives the centre at the start height). Trailing
//    numbers after r (NX writes tolerance, diameter, corner radius) are
//    ignored. Creo's multi-point GOTO (bare "x, y, z" records after a GOTO)
//    continues the GOTO; after a CIRCLE every such point ends one arc piece on
//    the same circle.
//  * CYCLE/DRILL: both the ISO 4343:1978 fixed-position form
//    `CYCLE/DRILL, depth, MMPM, feed, clearance` (the unit word may also follow
//    the feed: `CYCLE/DRILL,.4,20.,IPM,.1`) and the ISO 4343:2000 couplet form
//    of ICAM and NX (`CYCLE/DRILL,RAPTO,3,FEDTO,-10,RTRCTO,AUTO,MMPM,250`,
//    Fusion's `CYCLE/DRILL, FEDTO, d, MMPM, f, CLEAR, c, RTRCTO, r`). Each GOTO
//    while the cycle is on is a hole's top point P; levels are distances along
//    the tool axis a from P: rapid to P + clear·a, rapid to P + rapto·a, feed to
//    P − |depth|·a (NX writes FEDTO negative, Fusion positive), dwell, rapid to
//    P + rtrcto·a (AUTO or absent: the clearance). Pecking (DEEP, BRKCHP) is
//    one plunge, with a note.
//  * MSYS/x,y,z,xi,xj,xk,yi,yj,yk (NX: origin, X axis, Y axis of the MCS in the
//    part frame, Z = X × Y, as NX's UF_MTX3_initialize builds a frame from X
//    and Y) and the 12-number APT matrix (rows a1..a4, a5..a8, a9..a12,
//    point' = [a1 a2 a3]·p + a4, ... as GRIP and ICAM write it): following
//    coordinates, axes and circles are in that frame; the reader maps them to
//    the program (part) frame. CSYS is read the same way.
//  * FEDRAT/MMPR|IPR feeds per revolution follow the spindle speed in force at
//    each move; a feed move with one and no spindle speed is refused.
//  * SELCTL/n preselects the next tool (ICAM): a note, no tool change;
//    LOAD/TOOL, LOADTL and TOOLNO change the tool.
//  * Units: a UNITS record rules from where it stands. Siemens NX writes
//    none, so an inch CLSF says inch only in FEDRAT/IPM and the tool's size:
//    without a UNITS record the job's toolpath.units rules, else the unit of
//    the first feed (IPM/IPR: inch, MMPM/MMPR: mm), else mm; each with a note.
//  * Records that neither move the tool nor change how it moves (operator
//    text, display, vocabulary, tool preselection, vendor bookkeeping) are
//    skipped and noted once per word with the first line and the count; a
//    word that would change the path and is not modelled is refused.

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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

constexpr double kInch = 0.0254;
constexpr double kRpmToRadS = 2.0 * std::numbers::pi / 60.0;
constexpr std::string_view kUnitsKey = "toolpath.units";  // the job's key for AptOptions::units

// ---------------------------------------------------------------------------
// Records: physical lines joined by `$` continuations, comments removed.

struct Record {
  int line = 0;            // first physical line
  std::string word;        // major word, upper case ("GOTO", "TOOL PATH"); empty for a bare point
  std::string arguments;   // text after the '/', upper case
  bool has_slash = false;  // "RAPID/" and "RAPID" are the same; "GOTO" alone is not
};

// Major words whose argument is free text: a `$` or `$$` inside is not syntax.
std::string_view text_word(std::string_view upper_line) {
  for (std::string_view word : {"PARTNO", "PPRINT", "REMARK", "INSERT", "TPRINT", "TOOL PATH",
                                "OPERATION", "TITLES", "CLPRNT"})
    if (pt::starts_with_word(upper_line, word))
      return word;
  return {};
}

Record make_record(int line, std::string_view upper_text) {
  Record record;
  record.line = line;
  const std::size_t slash = upper_text.find('/');
  const std::string_view head = pt::trim(upper_text.substr(0, slash));
  // Collapse inner blanks of the major word ("TOOL  PATH" → "TOOL PATH").
  for (char c : head) {
    if (pt::is_blank(c)) {
      if (!record.word.empty() && record.word.back() != ' ')
        record.word += ' ';
    } else {
      record.word += c;
    }
  }
  if (slash != std::string_view::npos) {
    record.has_slash = true;
    record.arguments = std::string(pt::trim(upper_text.substr(slash + 1)));
  }
  // Creo's multi-point GOTO: lines of bare coordinates.
  if (slash == std::string_view::npos && !head.empty()) {
    const char c = head[0];
    if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') {
      record.word.clear();
      record.arguments = std::string(head);
    }
  }
  return record;
}

std::vector<Record> split_records(std::string_view text) {
  std::vector<Record> records;
  std::string pending;
  int pending_line = 0;
  int line = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string_view::npos)
      end = text.size();
    ++line;
    std::string upper = pt::to_upper(pt::trim(text.substr(begin, end - begin)));
    begin = end + 1;
    if (const std::string_view word = text_word(upper); pending.empty() && !word.empty()) {
      Record record;
      record.line = line;
      record.word = std::string(word);
      record.arguments = upper.substr(word.size());
      records.push_back(std::move(record));
      continue;
    }
    if (const std::size_t comment = upper.find("$$"); comment != std::string::npos)
      upper.erase(comment);
    std::string_view content = pt::trim(upper);
    const bool continues = !content.empty() && content.back() == '$';
    if (continues)
      content.remove_suffix(1);
    if (pending.empty() && content.empty() && !continues)
      continue;
    if (pending.empty())
      pending_line = line;
    pending += content;
    pending += ' ';
    if (!continues) {
      records.push_back(make_record(pending_line, pending));
      pending.clear();
    }
  }
  if (!pt::trim(pending).empty())
    records.push_back(make_record(pending_line, pending));
  return records;
}

// ---------------------------------------------------------------------------
// Arguments: numbers and minor words separated by commas.

struct Token {
  std::string_view text;
  std::optional<double> number;
  bool is_word() const { return !number.has_value(); }
};

// ---------------------------------------------------------------------------
// The reader's state while it walks the records.

enum class FeedBasis { per_minute, per_revolution };

struct Feed {
  FeedBasis basis = FeedBasis::per_minute;
  double metres = 0.0;  // per minute or per revolution
  int line = 0;
};

struct Circle {
  Vector3d centre_m;
  Vector3d normal;
  double radius_m = 0.0;  // 0: not written (CAMWorks' 6-number CIRCLE): the start's
  int line = 0;
};

// A skipped word's first line, its count and why it changes nothing.
struct SkippedWord {
  std::string word;
  int first_line = 0;
  int count = 0;
  std::string_view why;
};

struct DrillCycle {
  std::string kind;  // DRILL, DEEP, ...
  double depth_m = 0.0;
  double clear_m = 0.0;
  double rapto_m = 0.0;
  double retract_m = 0.0;
  std::optional<Feed> feed;  // the cycle's own feed, else the modal FEDRAT
  double dwell_s = 0.0;
  int line = 0;
};

class AptReader {
 public:
  explicit AptReader(const AptOptions& options) : options_(options) { program_.dialect = "apt"; }

  toolpath::Program read(std::string_view text);

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    throw InputError(options_.source_name, line, message);
  }
  void note(int line, const std::string& text) { program_.notes.push_back({line, text}); }
  void note_once(const std::string& key, int line, const std::string& text) {
    if (noted_.insert(key).second)
      note(line, text);
  }

  std::vector<Token> tokens(const Record& record) const;
  std::vector<double> numbers(const Record& record, std::string_view word) const;
  double length(double file_units) const { return file_units * length_m_per_unit_; }
  Vector3d point(const Record& record, const double* xyz) const;
  Vector3d direction(const Record& record, std::string_view word, const double* ijk) const;

  void dispatch(const Record& record);
  bool skip(const Record& record);
  void skipped(const Record& record, std::string_view why);
  void settle_units(const std::vector<Record>& records);
  void read_units(const Record& record);
  void read_fedrat(const Record& record);
  void read_spindl(const Record& record);
  void read_cutter(const Record& record, std::string_view word);
  void read_tool_change(const Record& record);
  void read_circle(const Record& record);
  void read_cycle(const Record& record);
  void read_frame(const Record& record);
  void read_goto(const Record& record, bool bare_point);
  void read_from(const Record& record);
  void read_delay(const Record& record);

  void go_to(const Record& record, const Vector3d& target, const Vector3d& axis);
  void drill(const Record& record, const Vector3d& top, const Vector3d& axis);
  void emit(MotionKind kind, const Vector3d& end, const Vector3d& axis_end, int line,
            const std::optional<Feed>& feed = std::nullopt);
  void finish(Move& move, int line, const std::optional<Feed>& feed);
  double feed_m_s(const Feed& feed, int line) const;
  double spindle_rad_s() const {
    return spindle_on_ ? spindle_sign_ * spindle_rpm_ * kRpmToRadS : 0.0;
  }

  const AptOptions& options_;
  toolpath::Program program_;
  std::set<std::string> noted_;

  double length_m_per_unit_ = kMillimetre;
  Eigen::Isometry3d frame_ = Eigen::Isometry3d::Identity();  // CL frame → program frame
  std::optional<Vector3d> position_;
  Vector3d position_axis_ = Vector3d::UnitZ();  // the tool axis at position_
  Vector3d axis_ = Vector3d::UnitZ();           // the modal axis of GOTOs without i, j, k
  std::optional<Feed> feed_;
  double spindle_rpm_ = 0.0;
  double spindle_sign_ = 1.0;
  bool spindle_on_ = false;
  int tool_ = 0;
  bool rapid_next_ = false;
  std::optional<Circle> circle_;      // waiting for the GOTO that ends it
  std::optional<Circle> arc_points_;  // the circle bare points continue on
  std::optional<DrillCycle> cycle_;
  std::optional<DrillCycle> last_cycle_;
  bool last_was_goto_ = false;
  std::optional<std::size_t> cutter_waiting_for_load_;  // a CUTTER that precedes its LOADTL
  std::optional<std::size_t> load_waiting_for_cutter_;  // a LOADTL that precedes its CUTTER
  bool stopped_ = false;
  std::vector<SkippedWord> skipped_;  // in the order first met
};

std::vector<Token> AptReader::tokens(const Record& record) const {
  std::vector<Token> result;
  if (pt::trim(record.arguments).empty())
    return result;
  for (std::string_view piece : pt::split_top_level(record.arguments)) {
    Token token{piece, pt::parse_number(piece)};
    if (token.is_word()) {
      bool plain = !piece.empty();
      for (char c : piece)
        plain = plain && ((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-');
      if (!plain || (piece[0] >= '0' && piece[0] <= '9'))
        fail(record.line, record.word + ": '" + pt::excerpt(piece) +
                              "' is neither a number nor a word; write numbers like -12.5 or "
                              "1.25E+01, separated by commas");
    }
    result.push_back(token);
  }
  return result;
}

std::vector<double> AptReader::numbers(const Record& record, std::string_view word) const {
  std::vector<double> values;
  for (std::string_view piece : pt::split_top_level(record.arguments)) {
    const std::optional<double> value = pt::parse_number(piece);
    if (!value)
      fail(record.line, std::string(word) + ": '" + pt::excerpt(piece) + "' is not a number; " +
                            std::string(word) + " takes numbers only, separated by commas");
    values.push_back(*value);
  }
  return values;
}

Vector3d AptReader::point(const Record&, const double* xyz) const {
  return frame_ * Vector3d(length(xyz[0]), length(xyz[1]), length(xyz[2]));
}

Vector3d AptReader::direction(const Record& record, std::string_view word,
                              const double* ijk) const {
  const Vector3d v(ijk[0], ijk[1], ijk[2]);
  const double norm = v.norm();
  if (!(norm > 1e-9) || !std::isfinite(norm))
    fail(record.line, std::string(word) +
                          ": the tool axis (i, j, k) is zero; write a unit vector from the tool "
                          "tip towards the spindle");
  return frame_.linear() * (v / norm);
}

toolpath::Program AptReader::read(std::string_view text) {
  if (text.size() > options_.max_bytes)
    fail(0, "the CL file has " + std::to_string(text.size()) + " bytes, more than the limit of " +
                std::to_string(options_.max_bytes) +
                "; split the program or raise the limit (toolpath.max_bytes)");
  program_.line_count = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) +
                        (!text.empty() && text.back() != '\n' ? 1 : 0);
  const std::vector<Record> records = split_records(text);
  settle_units(records);
  for (const Record& record : records) {
    if (stopped_)
      break;
    const bool goto_like = record.word == "GOTO" || record.word.empty();
    dispatch(record);
    last_was_goto_ = goto_like;
  }
  if (circle_)
    fail(circle_->line,
         "CIRCLE: no GOTO ends the arc; a CIRCLE record must be followed by the "
         "GOTO of the arc's end point");
  for (const SkippedWord& s : skipped_)
    note(s.first_line, s.word + " (" + std::to_string(s.count) + " record" +
                           (s.count == 1 ? "" : "s") + " from line " +
                           std::to_string(s.first_line) + "): " + std::string(s.why) + "; skipped");
  return std::move(program_);
}

// What a program says about its unit before its first UNITS record.
struct UnitEvidence {
  bool declared = false;                                  // a UNITS record before FINI
  std::optional<std::pair<int, std::string>> first_feed;  // line, "FEDRAT/IPM"
  bool feed_in_inches() const {
    return first_feed &&
           (first_feed->second.ends_with("IPM") || first_feed->second.ends_with("IPR"));
  }
};

UnitEvidence unit_evidence(const std::vector<Record>& records) {
  UnitEvidence evidence;
  for (const Record& record : records) {
    if (record.word == "FINI")
      break;
    if (record.word == "UNITS" || record.word == "UNIT")
      evidence.declared = true;
    if (evidence.first_feed || (record.word != "FEDRAT" && record.word != "CYCLE"))
      continue;
    for (std::string_view piece : pt::split_top_level(record.arguments)) {
      const std::string_view w = pt::trim(piece);
      if (w == "IPM" || w == "IPR" || w == "MMPM" || w == "MMPR") {
        evidence.first_feed = {record.line, record.word + "/" + std::string(w)};
        break;
      }
    }
  }
  return evidence;
}

// The unit of lengths before any UNITS record: the job's, else (no UNITS
// record) the first feed's, else millimetres (apt_leading_unit says the same).
AptOptions::Unit leading_unit(const UnitEvidence& evidence,
                              std::optional<AptOptions::Unit> job_units) {
  if (job_units)
    return *job_units;
  return !evidence.declared && evidence.feed_in_inches() ? AptOptions::Unit::inch
                                                         : AptOptions::Unit::mm;
}

void AptReader::settle_units(const std::vector<Record>& records) {
  using Unit = AptOptions::Unit;
  const UnitEvidence evidence = unit_evidence(records);
  const Unit unit = leading_unit(evidence, options_.units);
  length_m_per_unit_ = unit == Unit::inch ? kInch : kMillimetre;
  if (evidence.declared)
    return;  // the record rules (and must agree with the job's unit)
  const auto& first_feed = evidence.first_feed;
  if (options_.units) {
    note(0, std::string("no UNITS record: lengths read in ") +
                (unit == Unit::inch ? "inches" : "millimetres") + " (" + std::string(kUnitsKey) +
                ")");
  } else if (unit == Unit::inch) {
    note(first_feed->first,
         "no UNITS record: " + first_feed->second + " (line " + std::to_string(first_feed->first) +
             ") gives feeds in inches, so coordinates and tool sizes are read in inches; set " +
             std::string(kUnitsKey) + ": mm if they are millimetres");
  } else {
    note(first_feed ? first_feed->first : 0,
         "no UNITS record: coordinates read in millimetres" +
             (first_feed ? " (as " + first_feed->second + " on line " +
                               std::to_string(first_feed->first) + " gives feeds)"
                         : std::string()) +
             "; set " + std::string(kUnitsKey) + ": inch if they are inches");
  }
}

void AptReader::dispatch(const Record& record) {
  const std::string& word = record.word;
  if (word.empty()) {
    if (!last_was_goto_)
      fail(record.line, "'" + pt::excerpt(record.arguments) +
                            "': coordinates without a major word continue a GOTO only; write "
                            "GOTO/x, y, z");
    read_goto(record, true);
    return;
  }
  if (word == "GOTO")
    return read_goto(record, false);
  if (word == "FROM")
    return read_from(record);
  if (word == "RAPID") {
    rapid_next_ = true;
    return;
  }
  if (word == "FEDRAT")
    return read_fedrat(record);
  if (word == "SPINDL")
    return read_spindl(record);
  if (word == "UNITS" || word == "UNIT")
    return read_units(record);
  if (word == "TLAXIS") {
    const std::vector<double> v = numbers(record, word);
    if (v.size() < 3)
      fail(record.line, "TLAXIS: expected i, j, k (3 numbers), got " + std::to_string(v.size()));
    axis_ = direction(record, word, v.data());
    return;
  }
  if (word == "CIRCLE")
    return read_circle(record);
  if (word == "CYCLE")
    return read_cycle(record);
  if (word == "MSYS" || word == "CSYS")
    return read_frame(record);
  if (word == "CUTTER" || word == "TLDATA")
    return read_cutter(record, word);
  if (word == "LOAD" || word == "LOADTL" || word == "TOOLNO" || word == "SELCTL")
    return read_tool_change(record);
  if (word == "DELAY")
    return read_delay(record);
  if (word == "CUTCOM") {
    const std::string mode(pt::trim(record.arguments));
    if (mode == "OFF")
      return;
    fail(record.line, "CUTCOM/" + pt::excerpt(mode) +
                          ": cutter compensation is not modelled; output the tool centre path "
                          "(CUTCOM/OFF) from the CAM system");
  }
  if (word == "MULTAX") {
    const std::string mode(pt::trim(record.arguments));
    if (mode.empty() || mode == "ON" || mode == "OFF")
      return;
    fail(record.line, "MULTAX/" + pt::excerpt(mode) + ": expected MULTAX, MULTAX/ON or MULTAX/OFF");
  }
  if (word == "END") {  // end of a section: the machine stops, the program may go on
    spindle_on_ = false;
    rapid_next_ = false;
    return;
  }
  if (word == "FINI") {  // end of the part program: nothing after it runs
    stopped_ = true;
    return;
  }
  if (skip(record))
    return;
  // Words that would change the path and are not modelled: refused by name.
  static const std::set<std::string, std::less<>> kGeometryWords = {
      "GOFWD",  "GOLFT", "GORGT", "GOBACK", "GOUP", "GODOWN", "GO",   "GODLTA", "INDIRV",
      "INDIRP", "TLON",  "TLLFT", "TLRGT",  "PSIS", "POINT",  "LINE", "PLANE",  "PATERN"};
  if (kGeometryWords.count(word) != 0)
    fail(record.line, word +
                          ": APT part-programming statements are not modelled; output "
                          "cutter-location data (GOTO records) from the CAM system");
  if (word == "NURBS" || word == "KNOT" || word == "CNTRL" || word == "BSPLIN")
    fail(record.line, word +
                          ": spline motion is not modelled; output the path as GOTO points "
                          "(NX: NURBS output off in the machine control)");
  if (word == "MOVARC" || word == "GOHOME" || word == "TRANS" || word == "REFSYS" ||
      word == "COPY" || word == "INDEX" || word == "ROTATE" || word == "MIRROR" || word == "ORIGIN")
    fail(record.line, word +
                          " moves the tool or the frame in a way robomill does not model; "
                          "post the path as GOTO / CIRCLE records in one frame (MSYS/CSYS)");
  fail(record.line, "'" + pt::excerpt(word) +
                        "' is not an APT / CL major word robomill reads; remove it or post the "
                        "program as GOTO, FEDRAT, SPINDL, CIRCLE records");
}

// Records that neither move the tool nor change how it moves: counted and
// skipped. The list is closed (docs/toolpath.md, "Records skipped"); the one
// rule beyond it is a vendor namespace known to carry post-processor data
// only (CAMWorks' CSI_*). Returns false for anything else.
bool AptReader::skip(const Record& record) {
  struct Entry {
    std::string_view word, why;
  };
  static constexpr std::string_view kText = "operator text";
  static constexpr std::string_view kDisplay = "display on the CAM system's screen";
  static constexpr std::string_view kBook = "bookkeeping for the post-processor";
  static constexpr std::string_view kMachine = "a machine function that leaves the path as it is";
  static constexpr std::string_view kSpecific =
      "a machine-specific word with no modelled motion (its moves are in the GOTOs)";
  static constexpr Entry kList[] = {
      {"PARTNO", kText},     {"PPRINT", kText},
      {"REMARK", kText},     {"INSERT", kText},
      {"TPRINT", kText},     {"TOOL PATH", kText},
      {"OPERATION", kText},  {"TITLES", kText},
      {"CLPRNT", kText},     {"OPNAME", kText},
      {"PAINT", kDisplay},   {"DISPLY", kDisplay},
      {"PLABEL", kDisplay},  {"PPLOT", kDisplay},
      {"TMARK", kDisplay},   {"PPWORD", "vocabulary: declares a post-processor word (Creo)"},
      {"MACHIN", kBook},     {"SEQNO", kBook},
      {"AUTOPS", kBook},     {"INTOL", kBook},
      {"OUTTOL", kBook},     {"TOLER", kBook},
      {"LINTOL", kBook},     {"MCHTOL", kBook},
      {"MODE", kBook},       {"THICK", kBook},
      {"TURRET", kBook},     {"LEADER", kBook},
      {"REWIND", kBook},     {"END-OF-PATH", kBook},
      {"FINAL", kBook},      {"NOPOST", kBook},
      {"PPFUN", kBook},      {"OPSKIP", kBook},
      {"PREFUN", kBook},     {"AUXFUN", kBook},
      {"COOLNT", kMachine},  {"STOP", kMachine},
      {"OPSTOP", kMachine},  {"CLAMP", kMachine},
      {"ROTABL", kSpecific}, {"ROTHED", kSpecific},
      {"RETRCT", kSpecific}, {"SAFPOS", kSpecific},
      {"CLEARP", kSpecific}, {"SET", kSpecific},
      {"PITCH", kSpecific}};
  const std::string& word = record.word;
  for (const Entry& entry : kList)
    if (word == entry.word) {
      skipped(record, entry.why);
      return true;
    }
  if (word.starts_with("CSI_") && word.size() > 4) {
    skipped(record, "CAMWorks post-processor data (CSI_*: flute and extension lengths, ...)");
    return true;
  }
  if (word == "SELECT") {
    const std::vector<Token> list =
        tokens(record);  // NX: SELECT/TOOL, n after LOAD/TOOL readies the next tool
    if (list.size() == 2 && list[0].is_word() && list[0].text == "TOOL" && !list[1].is_word()) {
      skipped(record, "tool preselection ahead of a LOAD (the tool changes at LOAD/TOOL)");
      return true;
    }
    fail(record.line, "SELECT/" + pt::excerpt(record.arguments) +
                          ": only SELECT/TOOL, n (a tool preselection) is read");
  }
  if (word == "TRNTYP") {  // CAMWorks: TRNTYP/WORLD, 0, 0, 0 says "no transformation"
    const std::vector<Token> list = tokens(record);
    bool zero = !list.empty() && list[0].is_word() && list[0].text == "WORLD";
    for (std::size_t n = 1; zero && n < list.size(); ++n)
      zero = !list[n].is_word() && *list[n].number == 0.0;
    if (zero) {
      skipped(record, "a transformation of the world frame by zero: no change");
      return true;
    }
    fail(record.line, "TRNTYP/" + pt::excerpt(record.arguments) +
                          ": a coordinate transformation is not modelled (only TRNTYP/WORLD, 0, "
                          "0, 0 is read); post the path in one frame");
  }
  return false;
}

void AptReader::skipped(const Record& record, std::string_view why) {
  for (SkippedWord& s : skipped_)
    if (s.word == record.word) {
      ++s.count;
      return;
    }
  skipped_.push_back({record.word, record.line, 1, why});
}

void AptReader::read_units(const Record& record) {
  const std::string unit(pt::trim(record.arguments));
  AptOptions::Unit said;
  if (unit == "MM") {
    length_m_per_unit_ = kMillimetre;
    said = AptOptions::Unit::mm;
  } else if (unit == "INCHES" || unit == "INCH" || unit == "IN") {
    length_m_per_unit_ = kInch;
    said = AptOptions::Unit::inch;
  } else {
    fail(record.line, record.word + "/" + pt::excerpt(unit) + ": expected " + record.word +
                          "/MM or " + record.word + "/INCHES");
  }
  if (options_.units && *options_.units != said)
    fail(record.line, record.word + "/" + unit + " says the program is in " +
                          (said == AptOptions::Unit::mm ? "millimetres" : "inches") + ", but " +
                          std::string(kUnitsKey) + " says " +
                          (said == AptOptions::Unit::mm ? "inch" : "mm") +
                          "; make them agree (or remove " + std::string(kUnitsKey) +
                          ": the program's UNITS record rules)");
}

void AptReader::read_fedrat(const Record& record) {
  std::optional<double> value;
  Feed feed;
  feed.line = record.line;
  double unit_m = length_m_per_unit_;  // FEDRAT/250: per minute in the file's unit
  for (const Token& token : tokens(record)) {
    if (!token.is_word()) {
      if (value)
        fail(record.line, "FEDRAT: more than one number; write FEDRAT/MMPM, f or FEDRAT/f, MMPM");
      value = token.number;
      continue;
    }
    const std::string_view w = token.text;
    if (w == "MMPM" || w == "IPM" || w == "MMPR" || w == "IPR") {
      unit_m = (w[0] == 'M') ? kMillimetre : kInch;
      feed.basis = (w.back() == 'R') ? FeedBasis::per_revolution : FeedBasis::per_minute;
    } else if (w == "PERMIN") {
      feed.basis = FeedBasis::per_minute;
    } else if (w == "PERREV") {
      feed.basis = FeedBasis::per_revolution;
    } else {
      fail(record.line, "FEDRAT: '" + pt::excerpt(w) +
                            "' is not a feed unit; use MMPM, IPM, MMPR "
                            "or IPR");
    }
  }
  if (!value)
    fail(record.line, "FEDRAT: no feed value; write FEDRAT/MMPM, 250");
  if (!(*value > 0.0))
    fail(record.line, "FEDRAT: the feed must be positive, got " + pt::excerpt(record.arguments));
  feed.metres = *value * unit_m;
  feed_ = feed;
}

double AptReader::feed_m_s(const Feed& feed, int line) const {
  if (feed.basis == FeedBasis::per_minute)
    return feed.metres / 60.0;
  if (!(spindle_on_ && spindle_rpm_ > 0.0))
    fail(line, "FEDRAT/MMPR (line " + std::to_string(feed.line) +
                   ") is a feed per revolution but no spindle speed is in force; put "
                   "SPINDL/RPM, n before the move or give the feed per minute (MMPM)");
  return feed.metres * spindle_rpm_ / 60.0;
}

void AptReader::read_spindl(const Record& record) {
  const std::vector<Token> list = tokens(record);
  std::optional<double> rpm;
  bool off = false;
  for (std::size_t n = 0; n < list.size(); ++n) {
    const Token& token = list[n];
    if (!token.is_word()) {
      if (rpm)
        fail(record.line, "SPINDL: more than one speed; write SPINDL/RPM, n, CLW");
      rpm = token.number;
      continue;
    }
    const std::string_view w = token.text;
    if (w == "RPM") {
      continue;
    } else if (w == "CLW") {
      spindle_sign_ = 1.0;
    } else if (w == "CCW" || w == "CCLW") {
      spindle_sign_ = -1.0;
    } else if (w == "OFF") {
      off = true;
    } else if (w == "ON") {
      continue;
    } else if (w == "RANGE" || w == "MAXRPM") {
      if (n + 1 < list.size() && !list[n + 1].is_word())
        ++n;  // the range number or the speed limit: no effect on the cut
    } else if (w == "SFM" || w == "SMM") {
      fail(record.line, "SPINDL/" + std::string(w) +
                            ": constant surface speed is not modelled; post the spindle speed in "
                            "RPM");
    } else {
      fail(record.line,
           "SPINDL: '" + pt::excerpt(w) + "' is not a spindle word; use RPM, CLW, CCW, ON, OFF");
    }
  }
  if (off) {
    spindle_on_ = false;
    return;
  }
  if (rpm) {
    if (!(*rpm >= 0.0) || *rpm > 1e6)
      fail(record.line,
           "SPINDL: the speed must be between 0 and 1e6 RPM, got " + pt::excerpt(record.arguments));
    spindle_rpm_ = *rpm;
  } else if (spindle_rpm_ <= 0.0) {
    note_once("SPINDL/ON", record.line,
              "SPINDL/ON before any spindle speed: the spindle speed is 0");
  }
  spindle_on_ = true;
}

void AptReader::read_cutter(const Record& record, std::string_view word) {
  std::vector<double> values;
  std::string kind;
  for (const Token& token : tokens(record)) {
    if (token.is_word()) {
      if (!values.empty())
        fail(record.line, std::string(word) + ": '" + pt::excerpt(token.text) +
                              "' after the dimensions; write " + std::string(word) +
                              "/d, r, ... with numbers");
      kind += std::string(token.text) + " ";
    } else {
      values.push_back(*token.number);
    }
  }
  if (word == "TLDATA" &&
      !(pt::starts_with_word(kind, "MILL") || pt::starts_with_word(kind, "DRILL"))) {
    note(record.line, "TLDATA/" + pt::excerpt(kind) +
                          ": not a milling tool; its dimensions are "
                          "not checked");
    return;
  }
  if (word == "CUTTER" && !kind.empty())
    fail(record.line, "CUTTER/" + pt::excerpt(kind) +
                          ": only the numeric CUTTER/d, r, e, f, a, b, h form is read");
  if (values.empty())
    fail(record.line, std::string(word) + ": no diameter; write " + std::string(word) + "/d, r");
  if (!(values[0] > 0.0) || (values.size() > 1 && values[1] < 0.0))
    fail(record.line,
         std::string(word) + ": the diameter must be positive and the corner radius not negative");
  toolpath::ToolCall call;
  call.tool = tool_;
  call.line = record.line;
  call.diameter_m = length(values[0]);
  if (values.size() > 1)
    call.corner_radius_m = length(values[1]);
  if (load_waiting_for_cutter_) {  // LOADTL/n then CUTTER/d: one tool
    toolpath::ToolCall& load = program_.tool_calls[*load_waiting_for_cutter_];
    load.diameter_m = call.diameter_m;
    load.corner_radius_m = call.corner_radius_m;
    load_waiting_for_cutter_.reset();
    return;
  }
  program_.tool_calls.push_back(call);
  cutter_waiting_for_load_ = program_.tool_calls.size() - 1;  // CATIA: CUTTER then LOADTL
}

void AptReader::read_tool_change(const Record& record) {
  std::optional<double> number;
  const std::vector<Token> list = tokens(record);
  for (std::size_t n = 0; n < list.size(); ++n) {
    if (list[n].is_word()) {
      if (list[n].text == "ADJUST" || list[n].text == "LENGTH" || list[n].text == "OSETNO") {
        ++n;  // a length-offset register: no effect on the tip path
        continue;
      }
      if (list[n].text == "TOOL" || list[n].text == "MANUAL")
        continue;
      fail(record.line, record.word + ": '" + pt::excerpt(list[n].text) + "' is not read; write " +
                            record.word + "/n (the tool number)");
    }
    if (!number)
      number = list[n].number;  // LOADTL/n, m: m is the offset register
  }
  if (!number || *number < 0.0 || *number > 1e6 || std::floor(*number) != *number)
    fail(record.line, record.word + ": expected a tool number (a non-negative integer), got '" +
                          pt::excerpt(record.arguments) + "'");
  const int tool = static_cast<int>(*number);
  if (record.word == "SELCTL") {
    note(record.line, "SELCTL/" + std::to_string(tool) +
                          " preselects a tool; the tool changes at LOADTL / LOAD/TOOL");
    return;
  }
  tool_ = tool;
  if (cutter_waiting_for_load_) {
    program_.tool_calls[*cutter_waiting_for_load_].tool = tool;
    cutter_waiting_for_load_.reset();
    return;
  }
  program_.tool_calls.push_back({tool, record.line, std::nullopt, std::nullopt});
  load_waiting_for_cutter_ = program_.tool_calls.size() - 1;
}

void AptReader::read_circle(const Record& record) {
  const std::vector<double> v = numbers(record, "CIRCLE");
  // CAMWorks writes the centre and the axis only: the radius is the start's.
  if (v.size() < 6)
    fail(record.line, "CIRCLE: expected xc, yc, zc, i, j, k[, r] (6 or more numbers), got " +
                          std::to_string(v.size()));
  if (v.size() > 6 && !(v[6] > 0.0))
    fail(record.line, "CIRCLE: the radius must be positive");
  if (cycle_)
    fail(record.line, "CIRCLE inside a drill cycle; end the cycle with CYCLE/OFF first");
  circle_ = Circle{point(record, v.data()), direction(record, "CIRCLE", v.data() + 3),
                   v.size() > 6 ? length(v[6]) : 0.0, record.line};
}

void AptReader::read_frame(const Record& record) {
  const std::vector<double> v = numbers(record, record.word);
  Eigen::Matrix3d rotation;
  Vector3d origin;
  if (v.size() == 9) {
    origin = Vector3d(v[0], v[1], v[2]);
    const Vector3d x(v[3], v[4], v[5]);
    const Vector3d y(v[6], v[7], v[8]);
    if (!(x.norm() > 1e-9) || !(y.norm() > 1e-9))
      fail(record.line, record.word + ": a zero axis vector; write origin, X axis, Y axis");
    const Vector3d ux = x.normalized();
    const Vector3d uy = y.normalized();
    if (std::abs(ux.dot(uy)) > 1e-3)
      fail(record.line, record.word + ": the X and Y axes are not perpendicular (cos = " +
                            std::to_string(ux.dot(uy)) + ")");
    const Vector3d y_perp = (uy - ux.dot(uy) * ux).normalized();
    rotation.col(0) = ux;
    rotation.col(1) = y_perp;
    rotation.col(2) = ux.cross(y_perp);
  } else if (v.size() == 12) {
    rotation << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    origin = Vector3d(v[3], v[7], v[11]);
    const double error = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
    if (!(error < 1e-3) || !(rotation.determinant() > 0.0))
      fail(record.line, record.word +
                            ": the matrix is not a rotation (scaling, shear and mirroring are not "
                            "modelled); write a rigid frame");
    // Orthonormalize the columns against the matrix's rounding.
    const Vector3d ux = rotation.col(0).normalized();
    const Vector3d uy = (rotation.col(1) - ux.dot(rotation.col(1)) * ux).normalized();
    rotation.col(0) = ux;
    rotation.col(1) = uy;
    rotation.col(2) = ux.cross(uy);
  } else {
    fail(record.line, record.word +
                          ": expected 9 numbers (origin x, y, z, X axis, Y axis) or 12 "
                          "(a 3 x 4 matrix), got " +
                          std::to_string(v.size()));
  }
  frame_ = Eigen::Isometry3d::Identity();
  frame_.linear() = rotation;
  frame_.translation() = length_m_per_unit_ * origin;
  if (!frame_.isApprox(Eigen::Isometry3d::Identity(), 1e-12))
    note(record.line, record.word +
                          ": following coordinates are in this frame; robomill maps "
                          "them to the part frame");
}

void AptReader::read_cycle(const Record& record) {
  const std::vector<Token> list = tokens(record);
  if (list.empty() || !list[0].is_word())
    fail(record.line, "CYCLE: expected a cycle type (CYCLE/DRILL, ... or CYCLE/OFF)");
  const std::string_view type = list[0].text;
  if (type == "OFF") {
    cycle_.reset();
    return;
  }
  if (type == "ON") {
    if (!last_cycle_)
      fail(record.line, "CYCLE/ON: no cycle was defined before; write CYCLE/DRILL, ...");
    cycle_ = last_cycle_;
    return;
  }
  static const std::set<std::string, std::less<>> kPlunges = {"DRILL", "DEEP", "BRKCHP", "FACE",
                                                              "TAP",   "BORE", "REAM"};
  if (kPlunges.count(type) == 0)
    fail(record.line, "CYCLE/" + pt::excerpt(type) +
                          ": only plunge cycles (DRILL, DEEP, BRKCHP, FACE, TAP, BORE, REAM) are "
                          "modelled; post other cycles as GOTO moves");
  DrillCycle cycle;
  cycle.kind = std::string(type);
  cycle.line = record.line;
  std::optional<double> depth, clear, rapto, retract, feed_value;
  FeedBasis feed_basis = FeedBasis::per_minute;
  double feed_unit = length_m_per_unit_;
  int positional = 0;  // depth, feed, clearance in the ISO 4343:1978 order
  bool previous_was_feed = false;
  auto number_after = [&](std::size_t& n, std::string_view word) {
    if (n + 1 >= list.size() || list[n + 1].is_word())
      fail(record.line, "CYCLE: " + std::string(word) + " needs a number after it");
    return *list[++n].number;
  };
  for (std::size_t n = 1; n < list.size(); ++n) {
    const Token& token = list[n];
    if (!token.is_word()) {
      // Fill depth, feed, clearance in order, skipping those given by couplets.
      while (positional < 3 && ((positional == 0 && depth) || (positional == 1 && feed_value) ||
                                (positional == 2 && clear)))
        ++positional;
      if (positional == 0)
        depth = token.number;
      else if (positional == 1)
        feed_value = token.number;
      else if (positional == 2)
        clear = token.number;
      else
        fail(record.line, "CYCLE: more than three unnamed numbers (depth, feed, clearance)");
      previous_was_feed = positional == 1;
      ++positional;
      continue;
    }
    const std::string_view w = token.text;
    const bool was_feed = previous_was_feed;
    previous_was_feed = false;
    if (w == "MMPM" || w == "IPM" || w == "MMPR" || w == "IPR") {
      feed_unit = (w[0] == 'M') ? kMillimetre : kInch;
      feed_basis = (w.back() == 'R') ? FeedBasis::per_revolution : FeedBasis::per_minute;
      if (!was_feed)  // the unit before its value: a couplet
        feed_value = number_after(n, w);
    } else if (w == "DEPTH" || w == "FEDTO") {
      depth = number_after(n, w);
    } else if (w == "CLEAR") {
      clear = number_after(n, w);
    } else if (w == "RAPTO") {
      rapto = number_after(n, w);
    } else if (w == "RTRCTO" || w == "RETURN") {
      if (n + 1 < list.size() && list[n + 1].is_word() && list[n + 1].text == "AUTO")
        ++n;
      else
        retract = number_after(n, w);
    } else if (w == "DWELL") {
      cycle.dwell_s = number_after(n, w);
      if (n + 1 < list.size() && list[n + 1].is_word() && list[n + 1].text == "REV")
        fail(record.line, "CYCLE: DWELL in revolutions is not modelled; give it in seconds");
    } else if (w == "STEP" || w == "INCR" || w == "CHIPBK") {
      number_after(n, w);  // peck step: the plunge is modelled as one stroke
    } else if (w == "DEEP" || w == "BRKCHP" || w == "ORIENT" || w == "NODRAG" || w == "AUTO") {
      if (w == "DEEP" || w == "BRKCHP")
        cycle.kind += "," + std::string(w);
    } else {
      fail(record.line, "CYCLE: '" + pt::excerpt(w) +
                            "' is not a cycle parameter robomill reads (DEPTH/FEDTO, CLEAR, RAPTO, "
                            "RTRCTO, MMPM/IPM/MMPR/IPR, DWELL)");
    }
  }
  if (!depth || *depth == 0.0)
    fail(record.line, "CYCLE/" + cycle.kind + ": no depth; write CYCLE/" + cycle.kind +
                          ", depth, MMPM, feed, clearance");
  if (!(cycle.dwell_s >= 0.0) || cycle.dwell_s > 3600.0)
    fail(record.line, "CYCLE: the dwell must be between 0 and 3600 s");
  cycle.depth_m = length(std::abs(*depth));
  cycle.clear_m = length(clear.value_or(rapto.value_or(0.0)));
  cycle.rapto_m = length(rapto.value_or(clear.value_or(0.0)));
  cycle.retract_m = retract ? length(*retract) : cycle.clear_m;
  if (feed_value) {
    if (!(*feed_value > 0.0))
      fail(record.line, "CYCLE: the feed must be positive");
    cycle.feed = Feed{feed_basis, *feed_value * feed_unit, record.line};
  }
  if (cycle.kind != "DRILL")
    note_once("CYCLE/" + cycle.kind, record.line,
              "CYCLE/" + cycle.kind +
                  " is modelled as one feed plunge to the depth and a rapid "
                  "retract (no pecks, no spindle reversal)");
  cycle_ = cycle;
  last_cycle_ = cycle;
}

void AptReader::read_delay(const Record& record) {
  const std::vector<double> v = numbers(record, "DELAY");
  if (v.size() != 1 || !(v[0] >= 0.0) || v[0] > 3600.0)
    fail(record.line, "DELAY: expected one time in seconds between 0 and 3600");
  if (!position_) {
    note(record.line, "DELAY before the first position: ignored");
    return;
  }
  Move move;
  move.kind = MotionKind::dwell;
  move.start_m = move.end_m = *position_;
  move.axis_start = move.axis_end = axis_;
  move.dwell_s = v[0];
  move.spindle_rad_s = spindle_rad_s();
  move.tool = tool_;
  move.line = record.line;
  program_.moves.push_back(move);
}

void AptReader::read_from(const Record& record) {
  const std::vector<double> v = numbers(record, "FROM");
  if (v.size() != 3 && v.size() != 6)
    fail(record.line, "FROM: expected x, y, z or x, y, z, i, j, k, got " +
                          std::to_string(v.size()) + " numbers");
  if (v.size() == 6)
    axis_ = direction(record, "FROM", v.data() + 3);
  position_ = point(record, v.data());
  position_axis_ = axis_;
}

void AptReader::read_goto(const Record& record, bool bare_point) {
  const std::vector<double> v = numbers(record, "GOTO");
  if (v.size() != 3 && v.size() != 6)
    fail(record.line, "GOTO: expected x, y, z or x, y, z, i, j, k, got " +
                          std::to_string(v.size()) + " numbers");
  if (v.size() == 6)
    axis_ = direction(record, "GOTO", v.data() + 3);
  const Vector3d target = point(record, v.data());
  if (!bare_point)
    arc_points_.reset();
  if (bare_point && arc_points_)
    circle_ = arc_points_;  // Creo: every point after a CIRCLE ends a piece of it
  go_to(record, target, axis_);
}

void AptReader::go_to(const Record& record, const Vector3d& target, const Vector3d& axis) {
  if (cycle_)
    return drill(record, target, axis);
  if (!position_) {
    note(record.line, "the program's first point: no move before it is modelled");
    position_ = target;
    position_axis_ = axis;
    rapid_next_ = false;
    circle_.reset();
    return;
  }
  if (circle_) {
    const Circle circle = *circle_;
    circle_.reset();
    arc_points_ = circle;
    toolpath::ArcResult arc = toolpath::arc_from_centre(*position_, target, circle.centre_m,
                                                        circle.normal, /*clockwise=*/false);
    if (arc.problem == toolpath::ArcProblem::zero_radius)
      fail(record.line, "CIRCLE (line " + std::to_string(circle.line) +
                            "): the arc's start or end lies on the circle's axis");
    const double radius = circle.radius_m > 0.0 ? circle.radius_m : arc.start_radius_m;
    const double tolerance = std::max(1e-5, 1e-3 * radius);
    if (arc.problem != toolpath::ArcProblem::none ||
        std::abs(arc.start_radius_m - radius) > tolerance ||
        std::abs(arc.end_radius_m - radius) > tolerance)
      fail(record.line, "GOTO ending the CIRCLE of line " + std::to_string(circle.line) +
                            ": the start is " + std::to_string(arc.start_radius_m * 1e3) +
                            " mm and the end " + std::to_string(arc.end_radius_m * 1e3) +
                            " mm from the centre, but the radius is " +
                            std::to_string(radius * 1e3) +
                            " mm; the CIRCLE must describe the arc from the current point to "
                            "this GOTO");
    Move move = arc.move;
    move.axis_start = position_axis_;
    move.axis_end = axis;
    finish(move, record.line, feed_);
    rapid_next_ = false;
    return;
  }
  emit(rapid_next_ ? MotionKind::rapid : MotionKind::linear, target, axis, record.line);
  rapid_next_ = false;
}

void AptReader::drill(const Record& record, const Vector3d& top, const Vector3d& axis) {
  const DrillCycle& cycle = *cycle_;
  const Vector3d clear = top + cycle.clear_m * axis;
  const Vector3d rapid_to = top + cycle.rapto_m * axis;
  const Vector3d bottom = top - cycle.depth_m * axis;
  const Vector3d retract = top + cycle.retract_m * axis;
  const std::optional<Feed> feed = cycle.feed ? cycle.feed : feed_;
  if (!position_) {
    position_ = clear;
    position_axis_ = axis;
  }
  constexpr double kSame = 1e-12;
  if ((clear - *position_).norm() > kSame)
    emit(MotionKind::rapid, clear, axis, record.line);
  if ((rapid_to - *position_).norm() > kSame)
    emit(MotionKind::rapid, rapid_to, axis, record.line);
  emit(MotionKind::linear, bottom, axis, record.line, feed);
  if (cycle.dwell_s > 0.0) {
    Move dwell;
    dwell.kind = MotionKind::dwell;
    dwell.start_m = dwell.end_m = bottom;
    dwell.axis_start = dwell.axis_end = axis;
    dwell.dwell_s = cycle.dwell_s;
    dwell.spindle_rad_s = spindle_rad_s();
    dwell.tool = tool_;
    dwell.line = record.line;
    program_.moves.push_back(dwell);
  }
  emit(MotionKind::rapid, retract, axis, record.line);
  rapid_next_ = false;
}

void AptReader::emit(MotionKind kind, const Vector3d& end, const Vector3d& axis_end, int line,
                     const std::optional<Feed>& feed) {
  Move move;
  move.kind = kind;
  move.start_m = *position_;
  move.end_m = end;
  move.axis_start = position_axis_;
  move.axis_end = axis_end;
  finish(move, line, feed ? feed : feed_);
}

// Fills the modal part of a move (feed, spindle, tool, line), appends it and
// moves the current point to its end.
void AptReader::finish(Move& move, int line, const std::optional<Feed>& feed) {
  move.line = line;
  move.tool = tool_;
  move.spindle_rad_s = spindle_rad_s();
  if (move.kind != MotionKind::rapid) {
    if (feed)
      move.feed_m_s = feed_m_s(*feed, line);
    else
      note_once("no feed", line, "a feed move before any FEDRAT: its feed is 0");
  }
  program_.moves.push_back(move);
  position_ = move.end_m;
  position_axis_ = move.axis_end;
}

}  // namespace

toolpath::Program read_apt(std::string_view text, const AptOptions& options) {
  return AptReader(options).read(text);
}

AptOptions::Unit apt_leading_unit(std::string_view text, std::optional<AptOptions::Unit> units) {
  return leading_unit(unit_evidence(split_records(text)), units);
}

}  // namespace robomill::io
