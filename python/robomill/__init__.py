"""robomill: robotic milling from Python.

The same engine as the ``robomill`` command line: load a job (a YAML file or a
dict), override fields as ``--set`` does, run an analysis, and get its tables
as NumPy arrays and its key figures as a dict::

    import robomill
    job = robomill.Job("examples/demo.yaml", overrides={"process.ae": "2 mm"})
    result = robomill.stability(job)
    result["summary"]["min_limit_mm"]            # summary.json, as a dict
    result["sld"]["depth_limit_mm"]              # sld.csv's column, numpy.float64
    result["sld"]["bifurcation"]                 # a text column: list of str

Every analysis returns a dict: ``"summary"`` (summary.json), one entry per CSV
table the command writes, by file name without ``.csv`` (``"sld"``,
``"sld_envelope"``: ``{column: array}``), further JSON documents by name
without ``.json`` (``"advice"``), other files by their file name
(``"modes.yaml"``, ``"frf.uff"``) as str, and ``"message"``, the lines the
command prints. The tables hold full double precision; the CSV files the
command line writes round them to 12 significant digits.

Errors raise :class:`InputError` (a ``ValueError``; the command line's exit
code 2) or :class:`Error` (a ``RuntimeError``; exit code 1) with the command
line's message text. Computations release the GIL. See docs/python.md.
"""

from __future__ import annotations

import json as _json
import os as _os
from typing import Any, Iterable, Mapping, Optional, Union

from . import _robomill

__all__ = [
    "Error",
    "InputError",
    "Job",
    "advise",
    "analyze_signal",
    "atlas",
    "atlas_export",
    "deflection",
    "fit_modes",
    "forces",
    "frf",
    "identify_cutting",
    "identify_stiffness",
    "learn",
    "listen",
    "optimize",
    "robot",
    "simulate",
    "stability",
    "surface",
    "toolpath",
]
__version__ = "0.1.0"

Error = _robomill.Error
InputError = _robomill.InputError
Error.__module__ = "robomill"
InputError.__module__ = "robomill"

PathLike = Union[str, "os.PathLike[str]"]
Overrides = Union[Mapping[str, Any], Iterable[str], None]


def _override_value(value: Any) -> str:
    """A --set value: strings as typed (read as YAML: "2 mm", "[1, 2]"),
    anything else as its JSON text, which YAML reads back unchanged."""
    if isinstance(value, str):
        return value
    if isinstance(value, bool) or value is None:
        return _json.dumps(value)
    return _json.dumps(value, allow_nan=False)


def _override_pairs(overrides: Overrides) -> list:
    if overrides is None:
        return []
    if isinstance(overrides, Mapping):
        # Through the --set parser too: the same checks and messages.
        return [_robomill.parse_override(f"{path}={_override_value(value)}")
                for path, value in overrides.items()]
    if isinstance(overrides, str):
        overrides = [overrides]
    # "key.path=value" strings, read by the command line's --set parser.
    return [_robomill.parse_override(str(assignment)) for assignment in overrides]


class Job:
    """A validated job: a job file (or dict) plus ``--set``-style overrides.

    ``Job(path, overrides)`` reads a file; ``Job.from_dict(d)`` and
    ``Job.from_text(yaml)`` build one in memory. ``overrides`` maps dotted
    field paths to values (``{"process.ae": "2 mm", "forces.revolutions": 3}``)
    or is a list of ``"key.path=value"`` strings. Invalid jobs raise
    :class:`InputError` with the message ``robomill validate`` prints.
    Jobs are immutable: :meth:`with_overrides` returns a new one.
    """

    def __init__(self, path: PathLike, overrides: Overrides = None):
        self._handle = _robomill._Job.load(_os.fspath(path), _override_pairs(overrides))

    @classmethod
    def _wrap(cls, handle) -> "Job":
        job = cls.__new__(cls)
        job._handle = handle
        return job

    @classmethod
    def from_text(cls, text: str, base_dir: PathLike = ".", name: str = "<text>",
                  overrides: Overrides = None) -> "Job":
        """A job from YAML text; file paths in it are relative to ``base_dir``."""
        source = _os.path.join(_os.fspath(base_dir), name)
        return cls._wrap(_robomill._Job.parse(text, source, _override_pairs(overrides)))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], base_dir: PathLike = ".", name: str = "<dict>",
                  overrides: Overrides = None) -> "Job":
        """A job from a dict shaped like the YAML file (quantities as strings,
        ``{"process": {"ae": "4 mm"}}``); file paths in it are relative to
        ``base_dir``. The dict goes through the same parser as a file (as
        indented JSON, which is YAML), so messages name the same fields."""
        text = _json.dumps(data, indent=2, allow_nan=False)
        return cls.from_text(text, base_dir=base_dir, name=name, overrides=overrides)

    def with_overrides(self, overrides: Overrides) -> "Job":
        """A new job: this one's overrides followed by ``overrides``."""
        return Job._wrap(self._handle.with_overrides(_override_pairs(overrides)))

    def validate(self) -> list:
        """The sections present (``robomill validate``'s list); the job was
        validated when it was made, so this never raises."""
        return list(self._handle.sections)

    @property
    def source(self) -> str:
        """The job file, or ``base_dir/<dict>`` for an in-memory job."""
        return _os.fspath(self._handle.source)

    @property
    def name(self) -> str:
        return self._handle.name

    @property
    def overrides(self) -> dict:
        return dict(self._handle.overrides)

    @property
    def text(self) -> Optional[str]:
        """The YAML text of an in-memory job (None for a file)."""
        return self._handle.text

    def __repr__(self) -> str:
        extra = f", overrides={self.overrides!r}" if self._handle.overrides else ""
        return f"robomill.Job({self.source!r}{extra})"


def _job(job: Union[Job, PathLike, Mapping[str, Any]]):
    if isinstance(job, Job):
        return job._handle
    if isinstance(job, Mapping):
        return Job.from_dict(job)._handle
    return Job(job)._handle


def _out(out: Optional[PathLike]):
    return None if out is None else _os.fspath(out)


def _threads(threads: int) -> int:
    """--threads: 0 (all cores) or more."""
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 0:
        raise InputError(f"--threads: expected a whole number >= 0 (0: all cores), got {threads!r}")
    return threads


def _choice(option: str, value: str, allowed) -> str:
    if value not in allowed:
        raise InputError(f"{option}: '{value}': expected {' or '.join(a for a in allowed if a)}")
    return value


def _result(raw) -> dict:
    tables, documents, texts, summary, message = raw
    result: dict = {}
    if summary is not None:
        result["summary"] = _json.loads(summary)
    for name, columns in tables:
        result[name] = columns
    for name, text in documents:
        result[name] = _json.loads(text)
    for name, text in texts:
        result[name] = text
    result["message"] = message
    return result


def forces(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill forces``: force and torque over whole revolutions → "forces"."""
    return _result(_robomill.forces(_job(job), _threads(threads), _out(out)))


def stability(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill stability``: the lobe diagram → "sld" (+ "sld_envelope", "map")."""
    return _result(_robomill.stability(_job(job), _threads(threads), _out(out)))


def fit_modes(job, out: Optional[PathLike] = None) -> dict:
    """``robomill fit-modes``: modes from measured FRFs → "modes", "frf_fit",
    "stabilization", "modes.yaml"."""
    return _result(_robomill.fit_modes(_job(job), _out(out)))


def simulate(job, out: Optional[PathLike] = None) -> dict:
    """``robomill simulate``: time-domain simulation → "timeseries", "spectrum"."""
    return _result(_robomill.simulate(_job(job), _out(out)))


def robot(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill robot``: the robot at its posture → "frf", "modes" (+ "map")."""
    return _result(_robomill.robot(_job(job), _threads(threads), _out(out)))


def deflection(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill deflection``: tool and robot deformation over depths → "deflection"."""
    return _result(_robomill.deflection(_job(job), _threads(threads), _out(out)))


def optimize(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill optimize``: workpiece pose → "evaluations", "path" (+ "landscape")."""
    return _result(_robomill.optimize(_job(job), _threads(threads), _out(out)))


def advise(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill advise``: cutting-parameter advice → "advice", "advice_map"
    (+ "redundancy")."""
    return _result(_robomill.advise(_job(job), _threads(threads), _out(out)))


def learn(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill learn``: the uncertain inputs updated from the experiments
    (docs/learning.md) → "posterior" (one array per variable, one entry per
    sample), "lobes_quantiles" and "chatter_probability" (the posterior band),
    "lobes_quantiles_prior", "experiments", and in "summary" every variable's
    prior and posterior and the next test (summary["next_test"])."""
    return _result(_robomill.learn(_job(job), _threads(threads), _out(out)))


def surface(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill surface``: the Z-map surface (001) → "surface" (x_mm, y_mm, z_um
    nodes), "profiles", "surface.bmp" (bytes) and the roughness in "summary"."""
    return _result(_robomill.surface(_job(job), _threads(threads), _out(out)))


def toolpath(job, threads: int = 0, out: Optional[PathLike] = None,
             optimize: bool = False) -> dict:
    """``robomill toolpath``: the program over the stock → "samples" (one NumPy
    array per column of samples.csv; "motion" a list of words), "moves",
    "stock" (the final height map), "samples_preview" and the totals in
    "summary" (cutting_time_s, volume_removed_mm3, max_force_N, ...). With a
    robot on the program and ``optimize=True`` (``--optimize``): the better
    program as the text "program_optimized.<ext>" and the choices (ψ, spindle
    speeds, feeds under ``robot_path.feed_limits``) with the re-run's numbers
    in summary["optimization"]."""
    return _result(_robomill.toolpath(_job(job), _threads(threads), _out(out), bool(optimize)))


def listen(job, threads: int = 0, out: Optional[PathLike] = None) -> dict:
    """``robomill listen``: the chatter verdict of the job's recordings →
    "spectrum" (freq_hz, PSD, the cause of each bin), "spectrogram",
    "recordings" (with ``recordings:``), "sld" (with a stability section) and
    the verdict in "summary" (chatter, chatter_freq_hz, spindle_rpm_measured,
    recommended_spindle_rpm, ...)."""
    return _result(_robomill.listen(_job(job), _threads(threads), _out(out)))


def analyze_signal(samples, sample_rate_hz: float, spindle_rpm: float, teeth: int = 1,
                   full_scale: float = 0.0, ignore_hz=(), threshold: Optional[float] = None) -> dict:
    """The ``listen`` detector on samples in memory (a 1-D NumPy array, any
    unit): the keys of a recording in listen's summary.json — "verdict"
    ("stable", "chatter" or "unknown"), "reason", "chatter_freq_hz" (None
    unless the verdict is chatter; the strongest line no harmonic explains is
    "strongest_nonharmonic_hz"), "spindle_rpm_measured",
    "chatter_line_fraction" (the verdict's indicator, compared with
    ``threshold``: None is listen's default), "chatter_energy_fraction",
    "once_per_revolution_variance", "onset_s", "recommended_spindle_rpm" (within
    0.5-1.5 x ``spindle_rpm``), ... — and the spectra as arrays: "freq_hz",
    "psd", "cause", "spectrogram_t_s", "spectrogram_freq_hz",
    "spectrogram_psd" (frames x frequencies). ``full_scale`` > 0 enables the
    clipping check."""
    extra = {} if threshold is None else {"threshold": float(threshold)}
    return _robomill.analyze_signal(samples, float(sample_rate_hz), float(spindle_rpm), int(teeth),
                                    float(full_scale), [float(f) for f in ignore_hz], **extra)


def atlas(job, threads: int = 0, restart: bool = False) -> dict:
    """``robomill atlas``: every pending item of the job's workspace atlas
    (``atlas:`` and ``robot:`` sections) computed on threads and committed to
    its resumable SQLite store (``atlas.store``), exactly as the command line
    runs it; a second call resumes. Returns "computed", "already" (items the
    store held before), "done", "total", "threads", "elapsed_s" and "store".
    A store written by another job or version raises InputError unless
    ``restart``."""
    return dict(_robomill.atlas(_job(job), _threads(threads), bool(restart)))


def atlas_export(job, out: Optional[PathLike] = None) -> dict:
    """``robomill atlas --export``: the store's finished items → "atlas"
    (x_mm, y_mm, z_mm, redundancy_deg, lowest_fn_hz, depth_min_mm, ...) and
    "summary"; with ``out``, atlas.csv and summary.json written there."""
    return _result(_robomill.atlas_export(_job(job), _out(out)))


def frf(job, from_: str = "", to: str = "", step: str = "", spacing: str = "linear",
        points: int = 5000, kind: str = "receptance", format: str = "uff58", noise: float = 0.0,
        seed: int = 1, out: Optional[PathLike] = None) -> dict:
    """``robomill frf``: FRFs of the modal table → "frf.uff" or "frf_xx.csv" texts.
    Frequencies are quantities as typed after --from/--to/--step ("10 Hz")."""
    return _result(_robomill.frf(_job(job), str(from_), str(to), str(step), spacing, points, kind,
                                 format, noise, seed, _out(out)))


def identify_cutting(data: PathLike, job: Optional[PathLike] = None, teeth: str = "",
                     ap: str = "", ae: str = "", diameter: str = "", direction: str = "",
                     measured_on: str = "tool", out: Optional[PathLike] = None) -> dict:
    """``robomill identify-cutting DATA``: linear cutting coefficients → "fit",
    "cutting.yaml". Quantities as typed after --ap etc. ("3 mm")."""
    return _result(_robomill.identify_cutting(
        _os.fspath(data), "" if job is None else _os.fspath(job), str(teeth), str(ap), str(ae),
        str(diameter), _choice("--direction", direction, ("", "down", "up")),
        _choice("--measured-on", measured_on, ("tool", "workpiece")), _out(out)))


def identify_stiffness(data: PathLike, job, max_condition: float = 1e6,
                       synthesize: bool = False, noise: float = 0.0, seed: int = 1,
                       out: Optional[PathLike] = None) -> dict:
    """``robomill identify-stiffness DATA --job JOB``: joint stiffness → "fit",
    "joint_stiffness.yaml"; with ``synthesize`` the "loading_tests" table."""
    return _result(_robomill.identify_stiffness(_os.fspath(data), _job(job), max_condition,
                                                synthesize, noise, seed, _out(out)))
