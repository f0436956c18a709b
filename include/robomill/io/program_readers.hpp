#pragma once
// Readers of the programs a robot cell runs (DESIGN.md §1, the toolpath
// stage): ISO 6983 G-code, APT CL data and KUKA KRL, each into one
// toolpath::Program in SI units with the source line of every move. Parsing
// happens here, at the edge; the toolpath module sees only the Program.
//
// What a reader does not model is refused, never skipped: an InputError whose
// field is the program's name and whose line is the program line, naming the
// word and what to do instead ("pocket.nc (line 12): G41: cutter compensation
// is not modelled; post the program without compensation (G40), so that the
// path is the tool centre"). Words that change nothing robomill models (M8,
// G61, ...) are accepted; the ones a user may want to know about become
// Program::notes.

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "robomill/toolpath/program.hpp"

namespace robomill::io {

/// The dialects robomill reads and writes.
enum class ProgramFormat { gcode, apt, krl };

/// The length unit of an APT program's lengths before its first UNITS record
/// (NX writes none); unset: the first feed's unit, else mm.
enum class AptLengthUnit { unset, mm, inch };

/// Options every reader shares.
struct ProgramReadOptions {
  /// The program's name in messages (the file name as the job wrote it).
  std::string source_name = "program";
  /// Programs larger than this are refused before parsing (a 100 MB file is
  /// far beyond any real program of a robot cell; the limit is a job setting).
  std::size_t max_bytes = 64u << 20;
};

/// ISO 6983 G-code as CAM post-processors write it (docs/toolpath.md lists
/// every word): G0 G1 G2 G3 (I J K centres, R radius, full circles, helices),
/// G17 G18 G19, G20 G21, G90 G91, G90.1 G91.1, G94 F, S, M3 M4 M5, T M6,
/// G54-G59 (with `work_offsets`), N, ( ) and ; comments, % and O lines,
/// the preamble's modal words, G81 G82 G83 (G98/G99) as the plunges and
/// retracts they stand for, G4 dwells.
struct GcodeOptions : ProgramReadOptions {
  /// Work offsets G54 … G59 (index 1 … 6) in the program frame (m); a
  /// selected offset that is not given here is zero, with a note.
  std::map<int, Eigen::Vector3d> work_offsets_m;
  /// The machine's home height (G28/G30, G53 Z0) in the program frame (m).
  /// Posts retract with `G28 G91 Z0.` or `G53 G0 Z0.` before tool changes
  /// and at the end; with this set that retract is a rapid straight up to
  /// it, without it the tool stays where the post left it (at its clearance
  /// height) and a note says so. Home X and Y are never modelled (note).
  std::optional<double> home_z_m;
};
toolpath::Program read_gcode(std::string_view text, const GcodeOptions& options);

/// APT / CL data (ISO 4343-style, as CAM systems write it): GOTO/x,y,z[,i,j,k]
/// (the axis stays modal when omitted), FROM, FEDRAT (MMPM/IPM, either order),
/// SPINDL (RPM, CLW/CCW, OFF), RAPID, CUTTER/TLDATA, LOAD/TOOL and LOADTL,
/// MULTAX, UNITS/UNIT, CIRCLE (with the GOTO that ends it), CYCLE/DRILL, `$`
/// continuations and `$$` comments; MSYS/CSYS frames. Vendor records that
/// neither move the tool nor change how it moves (docs/toolpath.md lists
/// them) are skipped with a note giving their line and count.
struct AptOptions : ProgramReadOptions {
  /// The length unit of a program without a UNITS record (the job's
  /// `toolpath.units`): NX writes none, so an inch CLSF says inch only in
  /// its feeds. Unset: inch when the first feed is IPM/IPR, else mm (noted).
  /// A UNITS record that disagrees with a set unit is refused.
  enum class Unit { mm, inch };
  std::optional<Unit> units;
};
toolpath::Program read_apt(std::string_view text, const AptOptions& options);
/// The unit of an APT program's lengths before its first UNITS record, by
/// read_apt's rule (`units` if set; else, without a UNITS record, the first
/// feed's; else mm): for a writer that edits the program's numbers.
AptOptions::Unit apt_leading_unit(std::string_view text,
                                  std::optional<AptOptions::Unit> units = std::nullopt);

/// KUKA KRL: LIN, CIRC and PTP with {X, Y, Z, A, B, C} frames (mm, deg; A B C
/// the KUKA Z-Y'-X'' angles), positions named in the .dat file (DECL FRAME /
/// E6POS / POS, arrays filled in FOR loops), ;FOLD inline forms, $VEL.CP
/// (m/s), $BASE / $TOOL from BASE_DATA[n] / TOOL_DATA[n].
struct KrlOptions : ProgramReadOptions {
  /// The .dat file's text (may be empty) and its name for messages.
  std::string dat_text;
  std::string dat_name = "program.dat";
  /// BASE_DATA[n] in the program frame (the job's toolpath.bases); a
  /// program's positions are in the base in force. Unlisted bases: identity.
  std::map<int, Eigen::Isometry3d> bases;
  /// Which axis of the KRL tool frame points from the spindle into the work
  /// ('x': KUKA's default $TOOL_DIRECTION #X; 'z'): the tool axis tip →
  /// spindle is minus that axis.
  char tool_direction = 'x';
  /// FOR loops are unrolled; a program whose unrolled statements exceed this
  /// count is refused (a typo such as FOR I=1 TO 1000000 would otherwise
  /// build millions of moves).
  std::size_t max_executed_statements = 1'000'000;
};
toolpath::Program read_krl(std::string_view text, const KrlOptions& options);

}  // namespace robomill::io
