#pragma once
// report.html: one self-contained page per command (DESIGN.md §4, issue 10)
// with the figures that command's users expect, built from the command's own
// output files. The same function serves every command (from the files it
// is about to commit) and `robomill report OUTDIR` (from the files on disk),
// so a report can always be rebuilt from the results it shows.
//
// Plotly (npm plotly.js-dist-min, pinned in package.json) is embedded in the
// library at build time and inlined into every page: a report needs no
// network and no other file to be viewed.

#include <map>
#include <string>
#include <string_view>

namespace robomill::report {

/// A command's output files: file name → content.
using Files = std::map<std::string, std::string>;

/// The report of the command named by `summary.json`'s "command" key, from
/// the command's output files (CSV tables, summary.json, and inputs.json for
/// the key-inputs table; other files are listed). Figures use what is there:
/// a missing or malformed table leaves its figure out with a note. Throws
/// robomill::InputError when `summary.json` is missing or is not a JSON
/// object. The page never contains NaN or infinity (gaps are null).
std::string render_html(const Files& files);

/// The commands whose outputs have dedicated figures (other commands get the
/// tables and a generic plot of every CSV).
bool has_dedicated_figures(std::string_view command);

/// Plotly's minified source, as embedded at build time.
std::string_view plotly_js() noexcept;

}  // namespace robomill::report
