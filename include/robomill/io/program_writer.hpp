#pragma once
// A program written back in its own dialect with robomill's changes
// (`robomill toolpath JOB --optimize`, issue 19 item 5): statements inserted
// before given lines of the original text, or a line's own feed word
// rescaled, each with a comment that names the change, everything else byte
// for byte as the CAM post wrote it.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

namespace robomill::io {

/// A spindle speed set before a program line (1-based; line_count + 1: at
/// the end), with the comment written beside it.
struct SpindleEdit {
  int before_line = 0;
  double spindle_rad_s = 0.0;  ///< negative: counter-clockwise (M4, CCLW)
  std::string comment;
};

/// The feed of one program line (1-based) multiplied by `scale`, in the
/// program's own units and feed mode (the feed word in force is rescaled, so
/// inch programs, G95 feeds per revolution and FEDRAT/IPM stay what they
/// were). The line after the last of a run of edited lines gets the feed in
/// force in the original program back.
struct FeedEdit {
  int line = 0;
  double scale = 1.0;  ///< 1: the original feed in force, restored before this line
  /// The line's programmed path speed (m/s): KRL writes $VEL.CP absolute.
  double programmed_m_s = 0.0;
  std::string comment;
};

/// For every line of `text` (1-based; [0] unused) the line a statement
/// inserted for it must go before: the line itself, or in APT the first line
/// of the record it continues (a '$' continuation, or a GOTO's further points
/// on lines of their own). Feed edits are made per statement start.
std::vector<int> statement_starts(std::string_view text, ProgramFormat format);

/// The changes plus the restores that keep every other line at its
/// programmed feed: `changed` holds one edit per changed program line (scale
/// ≠ 1); a restore (scale 1) goes before the next feed line in the text after
/// a changed one, or — where `program` runs its lines out of order (a KRL FOR
/// loop) — before every unchanged feed line once a line has changed.
std::vector<FeedEdit> with_feed_restores(const toolpath::Program& program,
                                         std::vector<FeedEdit> changed);

/// G-code: a block `S<rpm> (<COMMENT>)` (the M3/M4 in force keeps the
/// direction); APT: `$$ <comment>` then `SPINDL/RPM,<rpm>,CLW|CCLW`. KRL
/// programs set no spindle speed (the cell's PLC does): InputError naming
/// `toolpath.format`. Comments lose characters the dialect cannot hold
/// (parentheses in G-code).
std::string write_spindle_edits(std::string_view text, ProgramFormat format,
                                std::vector<SpindleEdit> edits);

/// Both kinds of change in one pass. Feeds:
///  - G-code: the line's own F word rescaled, with `(comment)` appended; a
///    line without one gets a block `F<f> (comment)` before it, the F in
///    force rescaled. The restore is a block `F<f>` with the F in force.
///  - APT: `$$ comment` and the FEDRAT record in force with its number
///    rescaled before the line; the restore repeats that record as written.
///  - KRL: `$VEL.CP=<m/s> ; comment` before the line (after any inline
///    form's BAS call, so it governs the motion): the edit's scale times its
///    `programmed_m_s`; the restore sets the programmed path speed back.
/// Throws InputError (field `toolpath.file`, the program line) where a feed
/// cannot be rescaled as written: a G-code F written as an expression, no
/// feed word in force before the line.
std::string write_program_edits(std::string_view text, ProgramFormat format,
                                std::vector<SpindleEdit> spindles, std::vector<FeedEdit> feeds);

/// A move's programmed end point moved by `offset_m` (the program's own
/// frame, SI: the command turns the workpiece-frame offset back), with the
/// comment written beside it.
struct PointEdit {
  int line = 0;  ///< the line that programs the end point (one move on it)
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  /// Points written before the line: at the fraction u of the programmed
  /// line (start to end), moved by offset_m; u ascending inside (0, 1).
  struct Via {
    double u = 0.0;
    Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  };
  std::vector<Via> points;
  std::string comment;
  /// An arc's circle moved (the program's own frame, SI): its centre by
  /// centre_offset_m, its radius by radius_change_m. The arc starts where the
  /// line before was written to end, which must lie on the moved circle.
  struct Arc {
    Eigen::Vector3d centre_offset_m = Eigen::Vector3d::Zero();
    double radius_change_m = 0.0;
  };
  std::optional<Arc> arc;
};

/// The program with its point edits, and the edits it could not make.
struct PointEditResult {
  std::string text;
  struct Skipped {
    int line = 0;
    std::string reason;
  };
  std::vector<Skipped> skipped;
};

/// Moved end points and points added inside lines (the deflection
/// compensation of `--optimize`):
///  - G-code (absolute, G90): each added point a block `G1 X Y Z (comment)`
///    before the line (the first with the line's own F word, if it has one);
///    the line's X, Y, Z words replaced by the moved
///    values in the units in force (4 decimals in mm, 5 in inch), an axis the
///    line leaves modal appended with the value in force plus its offset,
///    `(comment)` added. An arc's I, J, K give the moved centre from the
///    start as written (G91.1; G90.1: the moved centre), its R the moved
///    radius. A later line that moves on with a modal axis the
///    edit changed gets that axis's programmed value back, so every other
///    point stays where it was. Skipped (with the reason): G91 incremental
///    lines, words written as expressions, a canned cycle in force, an axis
///    whose value in force is unknown (after G28/G30/G53 or a cycle).
///  - APT: the GOTO's x, y, z on that line rewritten, each added point a
///    `GOTO/x,y,z` before it; `$$ comment` before the record. An arc's
///    CIRCLE record gets the moved centre and radius. Skipped inside a frame
///    robomill does not read or a CYCLE, where the line holds fewer than
///    three coordinates, with added points where the GOTO is not a record of
///    its own with three coordinates, and for an arc whose CIRCLE serves
///    further points (arc pieces) or is not written as numbers.
///  - KRL: InputError naming `toolpath.format`: its points are moved where
///    the .src or the .dat writes them, by io::write_krl_point_edits.
/// `apt_units` is the job's toolpath.units: an APT program's lengths before
/// its first UNITS record are in the unit read_apt read them in.
PointEditResult write_point_edits(std::string_view text, ProgramFormat format,
                                  std::vector<PointEdit> edits,
                                  AptLengthUnit apt_units = AptLengthUnit::unset);

}  // namespace robomill::io
