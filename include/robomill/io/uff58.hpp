#pragma once
// Universal File Format dataset 58 ("function at nodal DOF"), the exchange
// format of hammer-test software, ASCII (58) and binary (58b). Only frequency
// response functions (function type 4) are kept; other function types
// (time responses, spectra, coherences) and other datasets are skipped, and a
// file without any FRF is rejected. Dataset 164 (units) is honoured.
//
// Conventions of the reader:
//  * Direction: record 6 directions 1/2/3 are +x/+y/+z of the tool frame;
//    -1/-2/-3 are the negative axes, so the data is negated once per negative
//    direction (response and reference) to give the FRF between the positive
//    axes. Directions 0 (scalar) and 4..6 (rotations) need an axis override.
//  * Kind: Uff58ReadOptions::kind when given; else the ordinate numerator's
//    specific data type (record 9: 8 displacement, 11 velocity, 12
//    acceleration; a unit label saying otherwise is an error); for type 0 or 1
//    its unit label. The denominator (record 10) must be a force (13, 9 or 0 =
//    unknown); the abscissa (record 8) frequency in Hz (18, or 0 read as Hz).
//  * Units: Uff58ReadOptions::ordinate_scale_to_si when given; otherwise the
//    unit labels of records 9 and 10 (m, mm, um, cm, in, ../s, ../s^2, g over
//    N, kN, mN, lbf; a record 9 label such as "mm/N" or "g/N" holds the whole
//    unit); where a label is empty or NONE, the factors of a preceding dataset
//    164 raised to the exponents the specific data type implies (Addendum A);
//    without 164, SI. An unrecognized label is an error rather than a guess.
//  * 58b: byte order 1 (little) or 2 (big endian), IEEE floats; the byte count
//    must match record 7 (the abscissa may be single precision, as in the
//    spec's Fortran; pyuff's 8 bytes per point is tolerated); a line break
//    between the data and the closing delimiter is tolerated.
//  * Every malformed input throws robomill::InputError(source name, 1-based
//    line, reason); lines count every '\n' of the file, binary blocks included.
//    At most 10 million points per function.
//
// The writer produces SI data (m, N, Hz; dataset 164 "SI" first), complex
// double ordinates (type 6), positive directions, and abscissa spacing even
// only when every frequency equals min + i·increment exactly. Numbers are
// written with 17 significant digits (fields of 25 columns, e.g.
// " -1.2345678901234567E-07", one point per line) instead of the classic
// 4E20.12/E13.5 fields, so that a write-then-read round trip is bit-exact;
// readers that split fields at fixed columns need the binary variant, which
// is exact and standard (little-endian IEEE doubles, the delimiter right
// after the data).

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/dynamics/frf.hpp"

namespace robomill::io {

/// One FRF read from or written to a dataset 58, with the file's metadata.
struct UffFrf {
  dynamics::Frf frf;                    ///< SI; frf.label is ID line 1 (record 1)
  std::array<std::string, 4> id_lines;  ///< records 2..5 (record 3 is usually a date)
  std::string response_entity = "NONE";
  int response_node = 1;
  std::string reference_entity = "NONE";
  int reference_node = 1;
  int line = 0;  ///< line of the dataset's start delimiter when read
};

struct Uff58ReadOptions {
  /// Factor from the file's ordinate unit to SI (1e-3 for mm/N, 9.80665 for
  /// g/N); when set it replaces the unit labels and dataset 164. Must be > 0.
  std::optional<double> ordinate_scale_to_si;
  /// What the ordinate measures, when the file does not say or says it wrongly.
  std::optional<dynamics::FrfKind> kind;
  /// Tool-frame axes (0..2) replacing the file's record 6 directions; the sign
  /// of a negative file direction still applies.
  std::optional<int> response_axis;
  std::optional<int> reference_axis;
};

enum class UffEncoding { ascii, binary };

/// Every FRF of a UFF file, in file order. Throws InputError (file, line, why).
std::vector<UffFrf> read_uff58(const std::filesystem::path& file,
                               const Uff58ReadOptions& options = {});
std::vector<UffFrf> parse_uff58(std::string_view bytes, std::string_view source_name,
                                const Uff58ReadOptions& options = {});

/// One time response (function type 1) of a dataset 58: a recorded signal at
/// a uniform rate. Read with the FRF reader's conventions (58 and 58b, line
/// numbers, dataset 164); the abscissa must be time (record 8 type 17 or 0,
/// unit s, ms or blank) and the ordinate real (data type 2 or 4). An unevenly
/// spaced record (time, value pairs) is accepted when its times are uniform
/// within 0.1 % of the first interval.
struct UffTimeRecord {
  /// SI (m, m/s, m/s^2, N, Pa) when unit_is_si; else as written in the file.
  std::vector<double> value;
  double dt_s = 0.0;     ///< sampling interval
  double start_s = 0.0;  ///< time of the first sample
  /// "m/s^2" ... when converted; otherwise the file's label (e.g. "V"),
  /// which no conversion is known for. Empty: the file does not say.
  std::string unit;
  bool unit_is_si = true;
  int specific_type = 0;  ///< record 9 ordinate specific data type (12: acceleration)
  std::string label;      ///< record 1
  std::array<std::string, 4> id_lines;
  std::string response_entity = "NONE";
  int response_node = 1;
  int response_direction = 0;  ///< record 6, as written (1..3 = +x..+z)
  int line = 0;                ///< line of the dataset's start delimiter when read
};

/// Every time record (function type 1) of a UFF file, in file order; other
/// datasets are skipped, a file without a time record is rejected. Throws
/// InputError (file, line, why).
std::vector<UffTimeRecord> read_uff58_time_records(const std::filesystem::path& file);
std::vector<UffTimeRecord> parse_uff58_time_records(std::string_view bytes,
                                                    std::string_view source_name);

/// The file content; throws std::invalid_argument for an invalid FRF.
std::string format_uff58(const std::vector<UffFrf>& frfs, UffEncoding encoding);
/// Written atomically (write_file_atomically).
void write_uff58(const std::filesystem::path& file, const std::vector<UffFrf>& frfs,
                 UffEncoding encoding);

/// Time records as dataset 58 function type 1 (real double ordinates, even
/// spacing, record 9 carrying `unit` and `specific_type`), after a dataset 164
/// "SI"; throws std::invalid_argument for an empty record, a non-positive dt
/// or a non-finite sample. Written atomically.
std::string format_uff58_time_records(const std::vector<UffTimeRecord>& records,
                                      UffEncoding encoding);
void write_uff58_time_records(const std::filesystem::path& file,
                              const std::vector<UffTimeRecord>& records, UffEncoding encoding);

}  // namespace robomill::io
