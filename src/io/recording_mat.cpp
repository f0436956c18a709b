// MATLAB .mat recordings through matio (v5 and, with matio's HDF5 support,
// v7.3). matio loads a variable whole; that is acceptable here because a
// recording variable is one matrix the user already held in MATLAB's memory,
// and only the chosen column is kept (as doubles) once it is read. The
// samples are then delivered in blocks like every other source.

#include <matio.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "recording_detail.hpp"
#include "robomill/io/recording.hpp"

namespace robomill::io {
namespace recording_detail {
namespace {

struct MatCloser {
  void operator()(mat_t* mat) const noexcept { Mat_Close(mat); }
};
struct VarFreer {
  void operator()(matvar_t* var) const noexcept { Mat_VarFree(var); }
};
using MatHandle = std::unique_ptr<mat_t, MatCloser>;
using VarHandle = std::unique_ptr<matvar_t, VarFreer>;

// matio reports its own errors on stderr by default; our messages say what
// went wrong, so its log is silenced (once, process-wide).
void quiet_matio_log(int, char*) {}
void silence_matio() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("robomill", quiet_matio_log); });
}

bool is_numeric(const matvar_t& var) {
  switch (var.class_type) {
    case MAT_C_DOUBLE:
    case MAT_C_SINGLE:
    case MAT_C_INT8:
    case MAT_C_UINT8:
    case MAT_C_INT16:
    case MAT_C_UINT16:
    case MAT_C_INT32:
    case MAT_C_UINT32:
    case MAT_C_INT64:
    case MAT_C_UINT64:
      return true;
    default:
      return false;
  }
}

std::size_t element_bytes(matio_classes type) {
  switch (type) {
    case MAT_C_DOUBLE:
    case MAT_C_INT64:
    case MAT_C_UINT64:
      return 8;
    case MAT_C_SINGLE:
    case MAT_C_INT32:
    case MAT_C_UINT32:
      return 4;
    case MAT_C_INT16:
    case MAT_C_UINT16:
      return 2;
    default:
      return 1;
  }
}

template <typename T>
double load(const void* data, std::size_t index) {
  T value;
  std::memcpy(&value, static_cast<const unsigned char*>(data) + index * sizeof(T), sizeof(T));
  return static_cast<double>(value);
}

// Element `index` (column-major) of a numeric variable, as a double.
double element(const matvar_t& var, std::size_t index) {
  switch (var.class_type) {
    case MAT_C_DOUBLE:
      return load<double>(var.data, index);
    case MAT_C_SINGLE:
      return load<float>(var.data, index);
    case MAT_C_INT8:
      return load<std::int8_t>(var.data, index);
    case MAT_C_UINT8:
      return load<std::uint8_t>(var.data, index);
    case MAT_C_INT16:
      return load<std::int16_t>(var.data, index);
    case MAT_C_UINT16:
      return load<std::uint16_t>(var.data, index);
    case MAT_C_INT32:
      return load<std::int32_t>(var.data, index);
    case MAT_C_UINT32:
      return load<std::uint32_t>(var.data, index);
    case MAT_C_INT64:
      return load<std::int64_t>(var.data, index);
    case MAT_C_UINT64:
      return load<std::uint64_t>(var.data, index);
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

// The names of the file's variables, and the numeric ones among them (read
// as headers only: no data is loaded here).
struct Catalogue {
  std::vector<std::string> names;
  std::vector<std::string> numeric;
  std::string listed() const {
    std::string out;
    for (const std::string& name : names)
      out += (out.empty() ? "" : ", ") + name;
    return out.empty() ? "no variables" : out;
  }
};

Catalogue catalogue(mat_t* mat) {
  Catalogue result;
  Mat_Rewind(mat);
  // A corrupt file could list forever; no recording file holds this many.
  for (int n = 0; n < 100000; ++n) {
    VarHandle var(Mat_VarReadNextInfo(mat));
    if (!var)
      break;
    const std::string name = var->name ? var->name : "";
    result.names.push_back(name);
    if (is_numeric(*var) && !var->isComplex)
      result.numeric.push_back(name);
  }
  Mat_Rewind(mat);
  return result;
}

int value_column(const RecordingSpec& spec, std::size_t columns) {
  if (spec.column.empty())
    return 2;
  std::size_t used = 0;
  int column = 0;
  try {
    column = std::stoi(spec.column, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != spec.column.size() || column < 1)
    fail(spec, "column",
         file_name(spec) +
             ": column must be a 1-based column number for a .mat "
             "file, got '" +
             spec.column + "'");
  if (column == 1)
    fail(spec, "column",
         file_name(spec) + ": column 1 is the time; the values are in columns 2.." +
             std::to_string(columns));
  if (static_cast<std::size_t>(column) > columns)
    fail(spec, "column",
         file_name(spec) + ": variable '" + spec.variable + "' has " + std::to_string(columns) +
             " columns, got column " + spec.column);
  return column;
}

// --- A structural check of MAT v5 files before matio sees them ---------------
// matio's v5 reader allocates what a header declares (the element array of a
// cell or struct) before it finds that the file cannot hold it; a corrupt
// 200-byte file can ask for gigabytes. This walk checks every cell and
// struct, nested ones too, against the bytes of its element (compressed
// elements are inflated, up to kMaxInflated, to check what they hold).

constexpr std::size_t kMaxInflated = std::size_t{64} << 20;
constexpr int kMaxDepth = 32;
enum : std::uint32_t { miINT32 = 5, miMATRIX = 14, miCOMPRESSED = 15 };

class V5Walk {
 public:
  explicit V5Walk(bool swap) : swap_(swap) {}

  // False when some element declares more than its bytes can hold.
  bool elements(std::string_view bytes, int depth) const {
    while (bytes.size() >= 8) {
      std::uint32_t type = 0, size = 0;
      std::string_view data;
      if (!tag(bytes, type, size, data))
        return false;
      if (type == miCOMPRESSED) {
        std::string inflated;
        if (inflate_capped(data, inflated) && !elements(inflated, depth))
          return false;
      } else if (type == miMATRIX && !matrix(data, depth)) {
        return false;
      }
    }
    return true;
  }

  // The array flags, dimensions and name of a matrix whose element begins
  // with `prefix` and holds `size` bytes in all: each must fit.
  bool header_fits(std::string_view prefix, std::size_t size) const {
    const std::size_t before = prefix.size();
    std::uint32_t type = 0, length = 0;
    std::string_view data;
    for (int k = 0; k < 3; ++k) {
      if (!tag(prefix, type, length, data))
        return false;
    }
    return before - prefix.size() <= size;
  }

 private:
  std::uint32_t u32(std::string_view bytes, std::size_t at) const {
    std::uint32_t value = 0;
    std::memcpy(&value, bytes.data() + at, 4);
    return swap_ ? __builtin_bswap32(value) : value;
  }

  // Splits off the next element (small or regular, padded to 8 bytes).
  bool tag(std::string_view& bytes, std::uint32_t& type, std::uint32_t& size,
           std::string_view& data) const {
    if (bytes.size() < 8)
      return false;
    const std::uint32_t first = u32(bytes, 0);
    if (first >> 16) {  // small data element: 2-byte size, 2-byte type, 4 bytes of data
      type = first & 0xFFFF;
      size = first >> 16;
      if (size > 4)
        return false;
      data = bytes.substr(4, size);
      bytes.remove_prefix(8);
      return true;
    }
    type = first;
    size = u32(bytes, 4);
    if (size > bytes.size() - 8)
      return false;
    data = bytes.substr(8, size);
    const std::size_t padded = type == miCOMPRESSED ? size : (std::size_t{size} + 7) / 8 * 8;
    bytes.remove_prefix(std::min(bytes.size(), 8 + padded));
    return true;
  }

  bool matrix(std::string_view data, int depth) const {
    if (depth > kMaxDepth)
      return false;
    std::uint32_t type = 0, size = 0;
    std::string_view flags, dims, name;
    if (!tag(data, type, size, flags) || flags.size() < 4 || !tag(data, type, size, dims) ||
        type != miINT32 || !tag(data, type, size, name))
      return false;  // matio would allocate the dimensions' declared size first
    const std::uint32_t class_type = u32(flags, 0) & 0xFF;
    if (class_type != MAT_C_CELL && class_type != MAT_C_STRUCT && class_type != MAT_C_OBJECT)
      return true;
    unsigned long long count = 1;
    for (std::size_t at = 0; at + 4 <= dims.size(); at += 4) {
      const std::uint32_t dim = u32(dims, at);
      if (dim != 0 && count > data.size() / dim)
        return false;
      count *= dim;
    }
    if (class_type != MAT_C_CELL) {
      std::string_view length, names;
      if (class_type == MAT_C_OBJECT && !tag(data, type, size, names))  // class name
        return false;
      if (!tag(data, type, size, length) || length.size() < 4 || !tag(data, type, size, names))
        return false;
      const std::uint32_t name_length = u32(length, 0);
      const std::size_t fields = name_length == 0 ? 0 : names.size() / name_length;
      if (fields != 0 && count > data.size() / fields)
        return false;
      count *= fields;
    }
    // Each element of a cell or struct is a matrix of at least one 8-byte tag.
    if (count > data.size() / 8)
      return false;
    return count == 0 || elements(data, depth + 1);
  }

  static bool inflate_capped(std::string_view in, std::string& out) {
    z_stream z{};
    if (inflateInit(&z) != Z_OK)
      return false;
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
    z.avail_in = static_cast<uInt>(in.size());
    int status = Z_OK;
    char buffer[16384];
    while (status == Z_OK && out.size() < kMaxInflated) {
      z.next_out = reinterpret_cast<Bytef*>(buffer);
      z.avail_out = sizeof buffer;
      status = inflate(&z, Z_NO_FLUSH);
      out.append(buffer, sizeof buffer - z.avail_out);
      if (status == Z_BUF_ERROR && z.avail_in == 0)
        break;  // truncated stream: check what was there
    }
    inflateEnd(&z);
    // Too large to check here: matio inflates it in blocks and finds the end.
    return out.size() < kMaxInflated;
  }

  bool swap_;
};

// The v5 walk over a whole file (its 128-byte header names the byte order).
// Top-level elements are read one at a time: a numeric matrix (the recording)
// is skipped by its size; cells, structs and compressed elements are loaded
// and walked, so memory stays near the largest of those.
void check_v5_structure(const RecordingSpec& spec) {
  std::ifstream stream(spec.file, std::ios::binary);
  char header[128];
  if (!stream.read(header, sizeof header))
    return;
  const bool swap = header[126] == 'M' && header[127] == 'I';
  const V5Walk walk(swap);
  std::string element;
  while (true) {
    char tag[8];
    if (!stream.read(tag, sizeof tag))
      return;
    std::uint32_t type = 0, size = 0;
    std::memcpy(&type, tag, 4);
    std::memcpy(&size, tag + 4, 4);
    if (swap) {
      type = __builtin_bswap32(type);
      size = __builtin_bswap32(size);
    }
    if (type >> 16)
      continue;  // a small element (8 bytes in all): nothing to allocate
    const std::size_t padded = type == miCOMPRESSED ? size : (std::size_t{size} + 7) / 8 * 8;
    bool load = type == miCOMPRESSED;
    if (type == miMATRIX) {
      // Array flags are the first subelement: its class says whether to look inside.
      char flags[16];
      const auto start = stream.tellg();
      if (size == 0)
        continue;  // an empty array: no subelements
      // Smaller than its array flags: matio would read the subelements from
      // what follows and allocate what they declare (a fuzz finding).
      if (size < 16)
        fail(spec, "file",
             file_name(spec) + ": a variable of " + std::to_string(size) +
                 " bytes is shorter than its array flags (corrupt MATLAB file?)");
      if (!stream.read(flags, sizeof flags))
        return;
      std::uint32_t word = 0;
      std::memcpy(&word, flags + 8, 4);
      const std::uint32_t class_type = (swap ? __builtin_bswap32(word) : word) & 0xFF;
      load = class_type == MAT_C_CELL || class_type == MAT_C_STRUCT || class_type == MAT_C_OBJECT;
      stream.seekg(start);
    }
    if (type == miMATRIX && !load) {
      // A numeric matrix (the recording): only its header is read here.
      element.resize(std::min<std::size_t>(size, 1 << 16));
      const auto start = stream.tellg();
      if (!stream.read(element.data(), static_cast<std::streamsize>(element.size())) ||
          !walk.header_fits(element, size))
        fail(spec, "file",
             file_name(spec) +
                 ": a variable's header is corrupt (its dimensions or "
                 "name do not fit; corrupt MATLAB file?)");
      stream.seekg(start);
    }
    if (!load || size > kMaxInflated) {
      stream.seekg(static_cast<std::streamoff>(padded), std::ios::cur);
      continue;
    }
    element.assign(tag, sizeof tag);
    element.resize(8 + std::size_t{size});
    if (!stream.read(element.data() + 8, size))
      return;  // truncated: matio reports it
    if (!walk.elements(element, 0))
      fail(spec, "file",
           file_name(spec) +
               ": a variable declares more elements than the file holds (corrupt "
               "MATLAB file?)");
    stream.seekg(static_cast<std::streamoff>(padded - size), std::ios::cur);
  }
}

// matio allocates what a variable's header declares before it reads the
// data: a corrupt header must not ask for more memory than the file could
// hold. Uncompressed data cannot exceed the file; zlib (v5 compressed
// variables, v7.3's HDF5 filters) expands at most about 1032-fold.
void check_declared_size(const RecordingSpec& spec, mat_t* mat, bool may_be_compressed) {
  VarHandle info(Mat_VarReadInfo(mat, spec.variable.c_str()));
  if (!info || info->rank < 1 || !info->dims)
    return;  // Mat_VarRead reports it
  long double declared = static_cast<long double>(element_bytes(info->class_type));
  for (int d = 0; d < info->rank; ++d)
    declared *= static_cast<long double>(info->dims[d]);
  std::error_code error;
  const auto file_bytes = static_cast<long double>(std::filesystem::file_size(spec.file, error));
  const bool compressed = may_be_compressed || info->compression != MAT_COMPRESSION_NONE;
  const long double limit = (compressed ? 1100.0L : 1.0L) * file_bytes + 4096.0L;
  if (!error && declared > limit)
    fail(spec, "variable",
         file_name(spec) + ": variable '" + spec.variable + "' declares " +
             number(static_cast<double>(declared)) + " bytes of data, more than the " +
             number(static_cast<double>(file_bytes)) + "-byte file can hold (corrupt file?)");
}

}  // namespace

std::unique_ptr<monitoring::SignalSource> open_mat(const RecordingSpec& spec) {
  silence_matio();
  {
    // v5 and v7.3 files open with a 128-byte header ending in the byte-order
    // mark "IM" (or "MI"). Anything else (v4, which has no header to check,
    // or not a MATLAB file) is refused before matio reads it: its v4 reader
    // allocates what the first bytes declare.
    std::ifstream stream(spec.file, std::ios::binary);
    char header[128] = {};
    const bool complete = static_cast<bool>(stream.read(header, sizeof header));
    const std::string_view mark(header + 126, 2);
    if (!complete || (mark != "IM" && mark != "MI"))
      fail(spec, "file",
           "cannot read " + file_name(spec) + " as a MATLAB file (expected a v5 or v7.3 .mat file" +
               (complete ? "; a v4 file must be saved again as v5 or v7.3)"
                         : ": it is shorter than the 128-byte header)"));
  }
  MatHandle mat(Mat_Open(spec.file.c_str(), MAT_ACC_RDONLY));
  if (!mat)
    fail(spec, "file",
         "cannot read " + file_name(spec) + " as a MATLAB file (expected a v5 or v7.3 .mat file)");
  const mat_ft version = Mat_GetVersion(mat.get());
  if (version != MAT_FT_MAT5 && version != MAT_FT_MAT73)
    fail(spec, "file", file_name(spec) + " is a MATLAB v4 file; save it as v5 or v7.3 (-v7.3)");

  if (version == MAT_FT_MAT5)
    check_v5_structure(spec);
  const Catalogue vars = catalogue(mat.get());
  std::string name = spec.variable;
  if (name.empty()) {
    if (vars.numeric.size() != 1)
      fail(spec, "variable",
           file_name(spec) + " holds " + std::to_string(vars.numeric.size()) +
               " numeric variables, name the one to read (it holds: " + vars.listed() + ")");
    name = vars.numeric.front();
  } else if (std::find(vars.names.begin(), vars.names.end(), name) == vars.names.end()) {
    fail(spec, "variable",
         "no variable '" + name + "' in " + file_name(spec) + " (it holds: " + vars.listed() + ")");
  }
  RecordingSpec named = spec;
  named.variable = name;

  check_declared_size(named, mat.get(), version == MAT_FT_MAT73);
  VarHandle var(Mat_VarRead(mat.get(), name.c_str()));
  if (!var)
    fail(named, "variable",
         file_name(spec) + ": cannot read variable '" + name + "' (corrupt file?)");
  if (!is_numeric(*var) || var->isComplex || var->rank != 2 || !var->dims)
    fail(named, "variable",
         file_name(spec) + ": variable '" + name +
             "' is not a real numeric matrix or vector (expected N×2 [time, "
             "value] or a vector)");
  const std::size_t rows = var->dims[0];
  const std::size_t columns = var->dims[1];
  // Column-major data of rows × columns elements; checked against what matio
  // holds before any element is touched.
  if (rows == 0 || columns == 0 || !var->data ||
      rows > std::numeric_limits<std::size_t>::max() / columns / 8 ||
      var->nbytes < rows * columns * element_bytes(var->class_type))
    fail(named, "variable", file_name(spec) + ": variable '" + name + "' holds no samples");

  std::vector<double> samples;
  const std::string where = name + " in " + file_name(spec) +
                            (version == MAT_FT_MAT73 ? " (MATLAB v7.3)" : " (MATLAB v5)");
  if (rows == 1 || columns == 1) {
    if (!spec.sample_rate_hz)
      fail(named, "sample_rate",
           file_name(spec) + ": variable '" + name +
               "' is a vector (no time column); give the sample_rate, or store [time, value] "
               "columns");
    const std::size_t count = rows * columns;
    samples.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      samples[i] = element(*var, i);
      if (!std::isfinite(samples[i]))
        fail(named, "variable",
             where + ": sample " + std::to_string(i + 1) + " is not a finite number");
    }
    var.reset();
    return memory_source(spec, std::move(samples), *spec.sample_rate_hz, 0.0,
                         where + ", vector of " + std::to_string(count));
  }

  const int column = value_column(named, columns);
  std::vector<double> time(rows);
  for (std::size_t r = 0; r < rows; ++r)
    time[r] = element(*var, r);
  const double rate = uniform_rate(named, time, "variable", "row");
  check_rate_agrees(spec, rate);
  const double time0 = time.front();
  time = {};
  samples.resize(rows);
  const std::size_t offset = static_cast<std::size_t>(column - 1) * rows;
  for (std::size_t r = 0; r < rows; ++r) {
    samples[r] = element(*var, offset + r);
    if (!std::isfinite(samples[r]))
      fail(named, "variable",
           where + ": row " + std::to_string(r + 1) + ", column " + std::to_string(column) +
               " is not a finite number");
  }
  var.reset();
  return memory_source(
      spec, std::move(samples), rate, time0,
      where + ", column " + std::to_string(column) + " of " + std::to_string(columns));
}

}  // namespace recording_detail
}  // namespace robomill::io
