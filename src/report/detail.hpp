#pragma once
// Internals of report.html: CSV tables, axis titles from column names, and
// Plotly figures as JSON (src/report/figures.cpp builds them per command,
// some commands' in src/report/figures_<command>.cpp; src/report/page.cpp
// lays out the page).

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/report/report.hpp"

namespace robomill::report::detail {

/// A CSV file with a header row, kept as text and read as numbers on demand.
class Table {
 public:
  static std::optional<Table> parse(std::string_view text);
  /// Only the `rows` rows with the largest finite numbers in `column` (the
  /// first of equal ones), in the text's order: what a table of the largest
  /// needs of a CSV too long to hold whole (a long program's moves.csv).
  /// Without the column, the whole table.
  static std::optional<Table> parse_largest(std::string_view text, const std::string& column,
                                            std::size_t rows);

  bool has(const std::string& column) const;
  const std::vector<std::string>& columns() const { return names_; }
  std::size_t rows() const { return rows_; }
  /// A column's numbers (NaN where a cell is not a number); empty if absent.
  std::vector<double> numbers(const std::string& column) const;
  const std::vector<std::string>& text(const std::string& column) const;
  /// The rows whose `column` reads `value`.
  Table where(const std::string& column, const std::string& value) const;
  /// A column's distinct texts in first-seen order.
  std::vector<std::string> distinct(const std::string& column) const;
  /// True if the column has a finite value other than zero.
  bool any_nonzero(const std::string& column) const;

 private:
  std::vector<std::string> names_;
  std::vector<std::vector<std::string>> cells_;  // by column
  std::size_t rows_ = 0;
};

/// "depth_limit_mm" → "limiting depth (mm)", "k_N_per_m" → "k (N/m)".
std::string axis_title(const std::string& column);
/// The unit of a column name ("mm", "N/m"), empty when none is recognized.
std::string column_unit(const std::string& column);
/// The quantity of a column name without its unit ("limiting depth").
std::string column_quantity(const std::string& column);

/// Numbers as a JSON array rounded to 6 significant digits; NaN and
/// infinities become null (a gap in Plotly), so no page ever holds NaN.
nlohmann::json values(const std::vector<double>& numbers);
/// Indices keeping at most `limit` of `count` samples, evenly strided.
std::vector<std::size_t> thin(std::size_t count, std::size_t limit);
std::vector<double> pick(const std::vector<double>& numbers, const std::vector<std::size_t>& at);
double rounded(double value);
/// A column's distinct finite values as the page shows them (rounded), sorted.
std::vector<double> levels_of(const std::vector<double>& values);

/// A Plotly figure: data traces and a layout, with a title and a caption.
struct Figure {
  std::string title;
  std::string caption;
  nlohmann::json data = nlohmann::json::array();
  nlohmann::json layout = nlohmann::json::object();
  int height_px = 460;
};

/// A scatter trace (lines by default) of x and y.
nlohmann::json trace(const std::vector<double>& x, const std::vector<double>& y,
                     const std::string& name, const std::string& mode = "lines");
/// An axis with a title (units included) and optional log type.
nlohmann::json axis(const std::string& title, bool log = false);
/// A figure of lines over one x axis.
Figure xy_figure(const std::string& title, const std::string& x_title, const std::string& y_title);
/// Stacks `rows` y axes (top first) over one shared x axis: layout axes
/// xaxis/yaxis, xaxis2/yaxis2 ... with the given titles and relative heights.
void stack(Figure& figure, const std::string& x_title, const std::vector<std::string>& y_titles,
           const std::vector<double>& weights = {});
/// Sends a trace to row `row` (0-based) of a stacked figure.
nlohmann::json& on_row(nlohmann::json& trace, int row);

/// A small table for the page: header and rows of display strings.
struct TextTable {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

/// What a command contributes to the page.
struct Content {
  std::vector<Figure> figures;
  std::vector<TextTable> tables;
  std::vector<std::string> notes;  ///< figures left out and why
};

/// The inputs of the figure builders: the files and the parsed summary.
struct Outputs {
  const Files& files;
  nlohmann::json summary;
  std::string command;
  /// A CSV output parsed, or nullopt (with a note) when absent or malformed.
  std::optional<Table> table(const std::string& name, Content& content, bool required = true) const;
  /// The same, with only the `rows` rows largest in `column` (Table::parse_largest).
  std::optional<Table> largest_rows(const std::string& name, const std::string& column,
                                    std::size_t rows, Content& content) const;
};

/// The figures and tables of `outputs.command` (figures.cpp).
Content build_content(const Outputs& outputs);
/// `robomill toolpath`: the path in 3-D, engagement and loads over time, the
/// final stock, the worst moves and the warnings (figures_toolpath.cpp).
void toolpath_figures(const Outputs& outputs, Content& content);

/// The cutting-process commands: `robomill forces` (forces and their
/// spectrum), `simulate` (forces, displacements and spectra over time),
/// `deflection` (the tool's deflection over the axial depth) and
/// `identify-cutting` (the identified law against the measured forces)
/// (figures_cutting.cpp).
void forces_figures(const Outputs& outputs, Content& content);
/// `stability` with an uncertainty: section: the quantile band over the
/// nominal lobe and the chatter-probability map (lobes_quantiles.csv,
/// chatter_probability.csv; figures_uncertainty.cpp). Nothing without them.
void stability_band_figures(const Outputs& outputs, Content& content);
/// `learn`'s figures: the prior and posterior bands with the tests and the
/// next one, the posterior P(chatter), the marginals, the correlations and
/// the chatter frequencies (figures_learning.cpp).
void learning_figures(const Outputs& outputs, Content& content);
/// A map of `value` over the position columns `coords` (the first two that
/// vary form the map; any further varying one becomes buttons). Rows whose
/// `mask` column is 0 (unreachable) are left blank. One varying coordinate
/// gives a line; none gives no figure (figures.cpp).
std::optional<Figure> grid_map(const Table& t, const std::vector<std::string>& coords,
                               const std::string& value, const std::string& title,
                               const std::string& mask = "reachable");
/// The job's cutting tests (summary.json's experiments) drawn on a figure of
/// spindle speed and depth: green circles stable, red crosses chatter
/// (figures.cpp).
void experiments_overlay(const Outputs& outputs, Figure& figure);
void simulate_figures(const Outputs& outputs, Content& content);
void deflection_figures(const Outputs& outputs, Content& content);
void identify_cutting_figures(const Outputs& outputs, Content& content);

/// Colour `i` of the figures' palette of 8 (figures.cpp).
const char* color(std::size_t i);
/// A line trace thinned to the figures' point limit, in palette colour
/// `color_index` (figures.cpp).
nlohmann::json line_trace(const std::vector<double>& x, const std::vector<double>& y,
                          const std::string& name, std::size_t color_index,
                          const std::string& dash = "solid");
/// A marker trace thinned to the figures' point limit (figures.cpp).
nlohmann::json marker_trace(const std::vector<double>& x, const std::vector<double>& y,
                            const std::string& name, const std::string& marker_color,
                            const std::string& symbol = "circle", double size = 6);
/// The values that are not positive as NaN (gaps on a log axis).
std::vector<double> positive_or_gap(std::vector<double> v);
/// summary[key] (or summary[key][sub]) as a number, NaN when absent or not
/// a number.
double summary_number(const nlohmann::json& summary, const std::string& key,
                      const std::string& sub = std::string());

/// Program line numbers as JSON integers (null when not finite): values()
/// keeps 6 significant digits, which would misname lines beyond 999 999.
nlohmann::json integer(double value);
nlohmann::json integers(const std::vector<double>& numbers);
/// Indices of at most `limit` of `y`'s samples keeping its extremes: per run
/// of consecutive samples, the smallest and the largest (a thinned force
/// trace still shows every peak, which an even stride would step over).
std::vector<std::size_t> envelope(const std::vector<double>& y, std::size_t limit);
/// With the robot along the path (samples_preview.csv has `margin`): adds the
/// chatter margin and the form error to the tool path's colour menu and hover.
/// `feed_rows`: the preview row of each point of the path's feed trace
/// (data[0]), samples.rows() at a gap (figures_toolpath_robot.cpp).
void robot_path_colours(const Table& samples, const std::vector<std::size_t>& feed_rows,
                        Figure& path);
/// With the robot along the path: margin, deflection and joints over time,
/// the form error on the part, the robot at its worst posture, the headline
/// and the worst lines with their advice; nothing for a folder without the
/// robot. `samples`: samples_preview.csv, null when absent
/// (figures_toolpath_robot.cpp).
void toolpath_robot_figures(const Table* samples, const nlohmann::json& summary, Content& content);
/// With draws of the uncertain inputs along the program (samples_preview.csv
/// has `p_chatter`; summary.json robot_along_path.uncertainty): the depth cut
/// against the nominal limit and the draws' band, P(chatter) with the bound
/// over time, and the lines over the bound (figures_uncertainty.cpp).
void path_uncertainty_figures(const Table* samples, const nlohmann::json& along, Content& content);
/// `robomill listen`: the spectrogram with the onset, the spectrum with each
/// line's cause, the recorded cuts on the lobes, the verdicts and the advice
/// (figures_listen.cpp).
void listen_figures(const Outputs& outputs, Content& content);
/// Every numeric column of a table over its first column: the fallback for
/// commands without dedicated figures.
void generic_figures(const std::string& file, const Table& table, Content& content);
/// Number formatting for tables: 4 significant digits, "—" for non-finite.
std::string display(double value);

}  // namespace robomill::report::detail
