#pragma once
// A program written back in its own dialect with robomill's changes
// (`robomill toolpath JOB --optimize`, issue 19 item 5): statements inserted
// before given lines of the original text, each with a comment that names
// the change, everything else byte for byte as the CAM post wrote it.

#include <string>
#include <string_view>
#include <vector>

#include "robomill/io/job.hpp"

namespace robomill::io {

/// A spindle speed set before a program line (1-based; line_count + 1: at
/// the end), with the comment written beside it.
struct SpindleEdit {
  int before_line = 0;
  double spindle_rad_s = 0.0;  ///< negative: counter-clockwise (M4, CCLW)
  std::string comment;
};

/// G-code: a block `S<rpm> (<COMMENT>)` (the M3/M4 in force keeps the
/// direction); APT: `$$ <comment>` then `SPINDL/RPM,<rpm>,CLW|CCLW`. KRL
/// programs set no spindle speed (the cell's PLC does): InputError naming
/// `toolpath.format`. Comments lose characters the dialect cannot hold
/// (parentheses in G-code).
std::string write_spindle_edits(std::string_view text, ToolpathSettings::Format format,
                                std::vector<SpindleEdit> edits);

}  // namespace robomill::io
