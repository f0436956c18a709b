"""Compare the Python module's results with the command line's files."""

import json
import math
import pathlib
import subprocess

# Wall-clock figures: the only summary values two runs of the same job may
# not share.
TIMING_KEYS = {"elapsed_s", "optimization_s", "advice_s", "grid_points_per_s"}


def strip_timings(value):
    if isinstance(value, dict):
        return {k: strip_timings(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [strip_timings(v) for v in value]
    return value


def csv_number(value: float) -> str:
    """A double as the command line writes it: 12 significant digits
    (std::to_chars general, which is printf's %.12g), never "-0"."""
    if math.isnan(value):
        return ""  # an empty cell: a value that does not apply (NaN in Python)
    if value == 0.0:
        value = 0.0
    assert math.isfinite(value)
    return "%.12g" % value


def csv_text(columns: dict) -> str:
    """A result table as the command line's CSV text."""
    names = list(columns)
    rows = len(columns[names[0]]) if names else 0
    lines = [",".join(names)]
    for r in range(rows):
        cells = []
        for name in names:
            cell = columns[name][r]
            cells.append(cell if isinstance(cell, str) else csv_number(float(cell)))
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def run_cli(cli, args, out: pathlib.Path, check=True):
    """`robomill ARGS --out OUT --quiet`; returns the completed process."""
    process = subprocess.run([cli, *map(str, args), "--out", str(out), "--quiet"],
                             capture_output=True, text=True)
    if check:
        assert process.returncode == 0, process.stderr
    return process


def assert_same_as_cli(result: dict, cli_dir: pathlib.Path, py_dir: pathlib.Path = None):
    """Every file the command line wrote equals the Python result: CSV tables
    to the last written digit, summary.json and other JSON documents key by
    key (but for wall-clock times), other files byte for byte. With py_dir
    (the result also written by Python's out=), the two folders hold the same
    files with the same bytes (JSON but for the times)."""
    files = sorted(p.name for p in cli_dir.iterdir())
    assert files, f"the command line wrote nothing into {cli_dir}"
    expected_keys = {"message"}
    for name in files:
        path = cli_dir / name
        stem, suffix = path.stem, path.suffix
        if name == "summary.json":
            assert strip_timings(result["summary"]) == strip_timings(json.loads(path.read_text()))
            expected_keys.add("summary")
        elif suffix == ".json":
            assert strip_timings(result[stem]) == strip_timings(json.loads(path.read_text()))
            expected_keys.add(stem)
        elif suffix == ".csv" and stem in result and isinstance(result[stem], dict):
            assert csv_text(result[stem]) == path.read_text(), f"{name} differs"
            for column in result[stem].values():
                if not isinstance(column, list):
                    assert column.dtype.name == "float64"
            expected_keys.add(stem)
        else:
            text = result[name]
            data = text if isinstance(text, bytes) else text.encode()
            assert data == path.read_bytes(), f"{name} differs"
            expected_keys.add(name)
    assert set(result) == expected_keys, "the result has entries the command line did not write"
    if py_dir is not None:
        assert sorted(p.name for p in py_dir.iterdir()) == files
        for name in files:
            a, b = (cli_dir / name).read_bytes(), (py_dir / name).read_bytes()
            if name.endswith(".json"):
                assert strip_timings(json.loads(a)) == strip_timings(json.loads(b)), name
            else:
                assert a == b, f"{name}: Python's file differs from the command line's"
