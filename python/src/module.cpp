// _robomill: the pybind11 extension behind the Python package `robomill`
// (python/robomill/__init__.py). It calls the same compute_<name> functions
// as the command line (the library's robomill/commands/commands.hpp), so a job gives the same
// numbers, tables and summary from either; tables come back as NumPy arrays
// at full double precision (the CSV files carry 12 significant digits).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "robomill/analysis/recording_verdicts.hpp"
#include "robomill/atlas/store.hpp"
#include "robomill/commands/command_result.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/summary.hpp"
#include "robomill/job/job.hpp"
#include "robomill/monitoring/recording_analysis.hpp"

namespace py = pybind11;
using robomill::commands::CommandResult;

namespace {

PyObject* error_type = nullptr;        // robomill.Error(RuntimeError)
PyObject* input_error_type = nullptr;  // robomill.InputError(robomill.Error, ValueError)

/// A validated job and how it was made, so that overrides can be added.
struct JobHandle {
  std::filesystem::path source;  ///< the file, or the name a text job goes by
  std::optional<std::string> text;
  std::vector<robomill::job::Override> overrides;
  std::shared_ptr<const robomill::job::Job> job;

  void parse() {
    robomill::job::Job parsed;
    {
      py::gil_scoped_release release;
      parsed = text ? robomill::job::parse_job(*text, source, overrides)
                    : robomill::job::load_job(source, overrides);
    }
    job = std::make_shared<const robomill::job::Job>(std::move(parsed));
  }
};

std::vector<robomill::job::Override> to_overrides(
    const std::vector<std::pair<std::string, std::string>>& pairs) {
  std::vector<robomill::job::Override> overrides;
  for (const auto& [path, value] : pairs)
    overrides.push_back({path, value});
  return overrides;
}

/// One column: float64 array when every cell is a number or empty (a value
/// that does not apply there, e.g. the chatter margin of a sample in the air:
/// NaN), else a list of str (numbers among words, which robomill does not
/// write, as float).
py::object column(const robomill::io::CsvTable& table, std::size_t c) {
  const std::size_t rows = table.rows();
  auto empty = [&](std::size_t r) {
    const std::string* word = std::get_if<std::string>(&table.cell(r, c));
    return word && word->empty();
  };
  bool numeric = true, any_number = false;
  for (std::size_t r = 0; r < rows && numeric; ++r) {
    const bool number = std::holds_alternative<double>(table.cell(r, c));
    any_number = any_number || number;
    numeric = number || empty(r);
  }
  if (numeric && (any_number || rows == 0)) {
    py::array_t<double> values(static_cast<py::ssize_t>(rows));
    double* data = values.mutable_data();
    for (std::size_t r = 0; r < rows; ++r)
      data[r] =
          empty(r) ? std::numeric_limits<double>::quiet_NaN() : std::get<double>(table.cell(r, c));
    return values;
  }
  py::list values;
  for (std::size_t r = 0; r < rows; ++r) {
    const auto& cell = table.cell(r, c);
    if (const std::string* word = std::get_if<std::string>(&cell))
      values.append(py::str(*word));
    else
      values.append(py::float_(std::get<double>(cell)));
  }
  return values;
}

/// (tables, documents, texts, summary, message): tables as a list of
/// (name, {column: values}), documents and the summary as summary.json text
/// (parsed on the Python side), texts as (file name, str or bytes).
py::tuple to_python(const CommandResult& result) {
  py::list tables;
  for (const auto& [name, table] : result.tables) {
    py::dict columns;
    for (std::size_t c = 0; c < table.columns().size(); ++c)
      columns[py::str(table.columns()[c])] = column(table, c);
    tables.append(py::make_tuple(name, columns));
  }
  py::list documents;
  for (const auto& [name, document] : result.documents)
    documents.append(py::make_tuple(name, robomill::io::summary_text(document)));
  py::list texts;
  for (const auto& [name, text] : result.texts) {
    // A binary UFF (frf --format uff58b) is not UTF-8 text.
    if (PyObject* decoded = PyUnicode_DecodeUTF8(text.data(), py::ssize_t(text.size()), nullptr)) {
      texts.append(py::make_tuple(name, py::reinterpret_steal<py::str>(decoded)));
    } else {
      PyErr_Clear();
      texts.append(py::make_tuple(name, py::bytes(text)));
    }
  }
  py::object summary = py::none();
  if (!result.summary.is_null())
    summary = py::str(robomill::io::summary_text(result.summary));
  return py::make_tuple(tables, documents, texts, summary, result.message);
}

/// Runs a computation without the GIL, writes the files when `out` is given
/// (exactly as the command line does), and converts the result.
template <class Compute>
py::tuple run(Compute&& compute, const std::optional<std::filesystem::path>& out,
              const robomill::job::OutputSettings& output, const robomill::job::Job* job) {
  CommandResult result;
  {
    py::gil_scoped_release release;
    result = compute();
    if (job)
      robomill::commands::add_key_inputs(result, *job);
    if (out)
      robomill::commands::write_result(*out, output, result);
  }
  return to_python(result);
}

const robomill::job::Job& job_of(const JobHandle& handle) {
  if (!handle.job)
    throw robomill::Error("the job was never loaded");
  return *handle.job;
}

/// The job as an atlas store records it: the file's (or text's) bytes and
/// each override as --set writes it, as the command line identifies it.
robomill::atlas::StoreIdentity atlas_identity(const JobHandle& handle) {
  const robomill::job::Job& job = job_of(handle);
  if (!job.robot)
    throw robomill::InputError("robot", 0,
                               "required by the atlas: the robot whose workspace it maps");
  std::vector<std::string> sets;
  for (const robomill::job::Override& o : handle.overrides)
    sets.push_back(o.path + "=" + o.value);
  const int dof = static_cast<int>(job.robot->description.joints.size());
  return handle.text ? robomill::commands::atlas_store_identity_of_text(*handle.text, sets, dof)
                     : robomill::commands::atlas_store_identity(handle.source, sets, dof);
}

void raise_input_error(const char* message, const std::string& field, int line) {
  py::object error = py::reinterpret_borrow<py::object>(input_error_type)(message);
  error.attr("field") = field;
  error.attr("line") = line;
  PyErr_SetObject(input_error_type, error.ptr());
}

using Out = std::optional<std::filesystem::path>;

/// robomill.Error and robomill.InputError, and the translation of C++ errors to them.
void register_errors(py::module_& m) {
  error_type = PyErr_NewException("robomill.Error", PyExc_RuntimeError, nullptr);
  py::tuple input_bases = py::make_tuple(py::handle(error_type), py::handle(PyExc_ValueError));
  input_error_type = PyErr_NewException("robomill.InputError", input_bases.ptr(), nullptr);
  m.attr("Error") = py::handle(error_type);
  m.attr("InputError") = py::handle(input_error_type);
  // The command line's exit code 2 (robomill: error: / invalid input:) is
  // InputError; its exit code 1 (robomill: failed:) is Error.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const robomill::InputError& e) {
      raise_input_error(e.what(), e.field(), e.line());
    } catch (const robomill::Error& e) {
      PyErr_SetString(error_type, e.what());
    } catch (const std::invalid_argument& e) {
      raise_input_error(e.what(), "", 0);
    }
  });
}

/// parse_override and the _Job class (a validated job and its overrides).
void register_jobs(py::module_& m) {
  m.def(
      "parse_override",
      [](const std::string& assignment) {
        const robomill::job::Override o = robomill::job::parse_override(assignment);
        return std::make_pair(o.path, o.value);
      },
      "`key.path=value` as --set reads it");

  py::class_<JobHandle>(m, "_Job")
      .def_static(
          "load",
          [](const std::filesystem::path& file,
             const std::vector<std::pair<std::string, std::string>>& overrides) {
            JobHandle handle;
            handle.source = file;
            handle.overrides = to_overrides(overrides);
            handle.parse();
            return handle;
          },
          py::arg("file"), py::arg("overrides"))
      .def_static(
          "parse",
          [](const std::string& text, const std::filesystem::path& source_name,
             const std::vector<std::pair<std::string, std::string>>& overrides) {
            JobHandle handle;
            handle.source = source_name;
            handle.text = text;
            handle.overrides = to_overrides(overrides);
            handle.parse();
            return handle;
          },
          py::arg("text"), py::arg("source_name"), py::arg("overrides"))
      .def("with_overrides",
           [](const JobHandle& self,
              const std::vector<std::pair<std::string, std::string>>& overrides) {
             JobHandle handle = self;
             for (const robomill::job::Override& o : to_overrides(overrides))
               handle.overrides.push_back(o);
             handle.parse();
             return handle;
           })
      .def_property_readonly("source", [](const JobHandle& h) { return h.source; })
      .def_property_readonly("text", [](const JobHandle& h) { return h.text; })
      .def_property_readonly("overrides",
                             [](const JobHandle& h) {
                               std::vector<std::pair<std::string, std::string>> pairs;
                               for (const auto& o : h.overrides)
                                 pairs.emplace_back(o.path, o.value);
                               return pairs;
                             })
      .def_property_readonly("name", [](const JobHandle& h) { return job_of(h).name; })
      .def_property_readonly("sections", [](const JobHandle& h) {
        return robomill::commands::job_sections(job_of(h));  // as `robomill validate` lists them
      });
}

/// A command on a job: name(job, threads=0, out=None), as the command line's.
void def_job_command(py::module_& m, const char* name,
                     CommandResult (*compute)(const robomill::job::Job&, int)) {
  m.def(
      name,
      [compute](const JobHandle& handle, int threads, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        return run([&] { return compute(job, threads); }, out, job.output, &job);
      },
      py::arg("job"), py::arg("threads") = 0, py::arg("out") = py::none());
}

/// The commands that take (job, threads, out) alone.
void register_job_commands(py::module_& m) {
  def_job_command(m, "forces", robomill::commands::compute_forces);
  def_job_command(m, "stability", robomill::commands::compute_stability);
  def_job_command(m, "robot", robomill::commands::compute_robot);
  def_job_command(m, "optimize", robomill::commands::compute_optimize);
  def_job_command(m, "advise", robomill::commands::compute_advise);
  def_job_command(m, "surface", robomill::commands::compute_surface);
  def_job_command(m, "learn", robomill::commands::compute_learn);
}

/// toolpath, listen, and the chatter detector on samples in memory.
void register_toolpath_and_listen(py::module_& m) {
  m.def(
      "toolpath",
      [](const JobHandle& handle, int threads, const Out& out, bool optimize) {
        const robomill::job::Job& job = job_of(handle);
        // In memory: the samples come back as arrays (the command line
        // streams them to samples.csv instead).
        return run(
            [&] { return robomill::commands::compute_toolpath(job, threads, {}, {}, optimize); },
            out, job.output, &job);
      },
      py::arg("job"), py::arg("threads") = 0, py::arg("out") = py::none(),
      py::arg("optimize") = false);
  def_job_command(m, "listen", [](const robomill::job::Job& job, int threads) {
    return robomill::commands::compute_listen(job, threads);
  });
  // The detector on samples already in memory (a NumPy array): the same
  // analysis `listen` runs on a file, its keys as listen's summary.json
  // writes a recording (commands::listen_recording_json), spectra back as
  // arrays.
  m.def(
      "analyze_signal",
      [](const py::array_t<double, py::array::c_style | py::array::forcecast>& samples,
         double sample_rate_hz, double spindle_rpm, int teeth, double full_scale,
         const std::vector<double>& ignore_hz, double threshold) {
        if (samples.ndim() != 1)
          throw robomill::InputError("samples", 0, "expected a one-dimensional array");
        std::vector<double> copy(samples.data(), samples.data() + samples.size());
        robomill::monitoring::ListenOptions options;
        options.commanded_spindle_hz = spindle_rpm / 60.0;
        options.teeth = teeth;
        options.chatter_line_threshold = threshold;
        for (double f : ignore_hz)
          options.ignore.push_back({f, 0.0});
        // A recording without a file, a depth or a diagram (no "depth_mm",
        // no "model"); the advice within half to one and a half times the
        // commanded speed.
        robomill::analysis::RecordingVerdict verdict;
        verdict.teeth = teeth;
        verdict.commanded_spindle_rad_s = options.commanded_spindle_hz * 2.0 * std::numbers::pi;
        {
          py::gil_scoped_release release;
          robomill::monitoring::VectorSource source(
              std::move(copy), sample_rate_hz, robomill::monitoring::SignalKind::sound, full_scale);
          robomill::analysis::judge_signal(source, options, 0.5 * options.commanded_spindle_hz,
                                           1.5 * options.commanded_spindle_hz, verdict);
        }
        const robomill::monitoring::RecordingAnalysis& a = verdict.analysis;
        // listen's keys through summary.json's text, as the commands' summaries.
        py::dict d(py::module_::import("json").attr("loads")(
            robomill::io::summary_text(robomill::commands::listen_recording_json(verdict))));
        const auto array = [](const std::vector<double>& v) {
          py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
          std::copy(v.begin(), v.end(), out.mutable_data());
          return out;
        };
        py::list causes;
        for (auto c : a.cause)
          causes.append(py::str(robomill::monitoring::line_cause_name(c)));
        py::array_t<double> spectrogram(
            {static_cast<py::ssize_t>(a.spectrogram_time_s.size()),
             static_cast<py::ssize_t>(a.spectrogram_frequency_hz.size())});
        std::copy(a.spectrogram_psd.begin(), a.spectrogram_psd.end(), spectrogram.mutable_data());
        d["freq_hz"] = array(a.frequency_hz);
        d["psd"] = array(a.psd);
        d["cause"] = causes;
        d["spectrogram_t_s"] = array(a.spectrogram_time_s);
        d["spectrogram_freq_hz"] = array(a.spectrogram_frequency_hz);
        d["spectrogram_psd"] = spectrogram;
        return d;
      },
      py::arg("samples"), py::arg("sample_rate_hz"), py::arg("spindle_rpm"), py::arg("teeth") = 1,
      py::arg("full_scale") = 0.0, py::arg("ignore_hz") = std::vector<double>{},
      py::arg("threshold") = robomill::monitoring::ListenOptions{}.chatter_line_threshold);
}

/// deflection, fit_modes, simulate and frf.
void register_model_commands(py::module_& m) {
  m.def(
      "deflection",
      [](const JobHandle& handle, int threads, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        return run([&] { return robomill::commands::compute_deflection(job, threads); }, out,
                   job.output, &job);
      },
      py::arg("job"), py::arg("threads") = 0, py::arg("out") = py::none());
  m.def(
      "fit_modes",
      [](const JobHandle& handle, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        return run([&] { return robomill::commands::compute_fit_modes(job); }, out, job.output,
                   &job);
      },
      py::arg("job"), py::arg("out") = py::none());
  m.def(
      "simulate",
      [](const JobHandle& handle, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        return run([&] { return robomill::commands::compute_simulate(job); }, out, job.output,
                   &job);
      },
      py::arg("job"), py::arg("out") = py::none());
  m.def(
      "frf",
      [](const JobHandle& handle, const std::string& from, const std::string& to,
         const std::string& step, const std::string& spacing, int points, const std::string& kind,
         const std::string& format, double noise, std::uint32_t seed, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        robomill::commands::FrfSettings options;
        options.from = from;
        options.to = to;
        options.step = step;
        options.spacing = spacing;
        options.points = points;
        options.kind = kind;
        options.format = format;
        options.noise_relative = noise;
        options.seed = seed;
        return run([&] { return robomill::commands::compute_frf(job, options); }, out, job.output,
                   &job);
      },
      py::arg("job"), py::arg("from_"), py::arg("to"), py::arg("step"), py::arg("spacing"),
      py::arg("points"), py::arg("kind"), py::arg("format"), py::arg("noise"), py::arg("seed"),
      py::arg("out") = py::none());
}

/// atlas (computing into its store) and atlas_export.
void register_atlas(py::module_& m) {
  m.def(
      "atlas",
      [](const JobHandle& handle, int threads, bool restart) {
        const robomill::job::Job& job = job_of(handle);
        const robomill::atlas::StoreIdentity identity = atlas_identity(handle);
        robomill::commands::AtlasRunOptions options;
        options.threads = threads;
        options.restart = restart;
        robomill::commands::AtlasRun run;
        {
          py::gil_scoped_release release;
          run = robomill::commands::run_atlas(job, identity, options);
        }
        py::dict report;
        report["computed"] = run.computed;
        report["already"] = run.already;
        report["done"] = run.done;
        report["total"] = run.total;
        report["threads"] = run.threads;
        report["elapsed_s"] = run.elapsed_s;
        report["store"] = job.atlas->store;
        return report;
      },
      py::arg("job"), py::arg("threads") = 0, py::arg("restart") = false);
  m.def(
      "atlas_export",
      [](const JobHandle& handle, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        if (!job.atlas)
          throw robomill::InputError("atlas", 0,
                                     "required: the atlas: section (grid, analyses, store)");
        const robomill::atlas::StoreIdentity identity = atlas_identity(handle);
        return run(
            [&] {
              try {
                return robomill::commands::compute_atlas_export(job, identity);
              } catch (const robomill::atlas::StoreMismatch& mismatch) {
                throw robomill::InputError("atlas.store", 0, mismatch.what());
              }
            },
            out, robomill::job::OutputSettings{}, &job);
      },
      py::arg("job"), py::arg("out") = py::none());
}

/// identify_cutting and identify_stiffness.
void register_identification(py::module_& m) {
  m.def(
      "identify_cutting",
      [](const std::filesystem::path& data, const std::filesystem::path& job_file,
         const std::string& teeth, const std::string& ap, const std::string& ae,
         const std::string& diameter, const std::string& direction, const std::string& measured_on,
         const Out& out) {
        robomill::commands::IdentifyCuttingInputs options;
        options.data_file = data;
        options.job_file = job_file;
        options.teeth = teeth;
        options.axial_depth = ap;
        options.radial_depth = ae;
        options.diameter = diameter;
        options.direction = direction;
        options.measured_on = measured_on;
        return run([&] { return robomill::commands::compute_identify_cutting(options); }, out,
                   robomill::job::OutputSettings{}, nullptr);
      },
      py::arg("data"), py::arg("job_file"), py::arg("teeth"), py::arg("ap"), py::arg("ae"),
      py::arg("diameter"), py::arg("direction"), py::arg("measured_on"),
      py::arg("out") = py::none());
  m.def(
      "identify_stiffness",
      [](const std::filesystem::path& data, const JobHandle& handle, double max_condition,
         bool synthesize, double noise, std::uint32_t seed, const Out& out) {
        const robomill::job::Job& job = job_of(handle);
        robomill::commands::IdentifyStiffnessSettings options;
        options.data_file = data;
        options.max_condition = max_condition;
        options.synthesize = synthesize;
        options.noise = noise;
        options.seed = seed;
        return run([&] { return robomill::commands::compute_identify_stiffness(job, options); },
                   out, robomill::job::OutputSettings{}, &job);
      },
      py::arg("data"), py::arg("job"), py::arg("max_condition"), py::arg("synthesize"),
      py::arg("noise"), py::arg("seed"), py::arg("out") = py::none());
}

}  // namespace

PYBIND11_MODULE(_robomill, m) {
  m.doc() = "robomill's C++ engine (use the package `robomill`, not this module)";

  register_errors(m);
  register_jobs(m);
  register_job_commands(m);
  register_toolpath_and_listen(m);
  register_model_commands(m);
  register_atlas(m);
  register_identification(m);
}
