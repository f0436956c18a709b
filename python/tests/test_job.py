"""Jobs from files and dicts, overrides, and errors with the command line's
messages."""

import json
import subprocess

import numpy as np
import pytest

import robomill

from equality import assert_same_as_cli, run_cli, strip_timings

DEMO_DICT = {
    "tool": {"type": "flat", "diameter": "24 mm", "teeth": 2, "helix": "60 deg",
             "overhang": "60 mm"},
    "cutting": {"law": "linear", "Ktc": "855.00 N/mm^2", "Krc": "270.93 N/mm^2",
                "Kte": "15.64 N/mm", "Kre": "14.167 N/mm"},
    "process": {"spindle": "1000 rpm", "feed_per_tooth": "0.12 mm", "ap": "2 mm", "ae": "4 mm",
                "direction": "up"},
    "forces": {"revolutions": 1, "steps_per_tooth": 90},
    "dynamics": {"modes": [
        {"direction": "y", "fn": "19.88 Hz", "zeta": "0.81 %", "k": "3.65e6 N/m"},
        {"direction": "x", "fn": "17.8 Hz", "zeta": "1.76 %", "k": 2.31e6},
    ]},
    "stability": {"method": "zoa", "speeds": {"from": "300 rpm", "to": "6000 rpm", "count": 25},
                  "depth_max": "10 mm"},
}


def test_results_are_numpy_and_dicts(source):
    result = robomill.stability(source / "examples" / "demo.yaml")
    assert isinstance(result["summary"], dict) and result["summary"]["method"] == "zoa"
    sld = result["sld"]
    assert list(sld) == ["spindle_rpm", "depth_limit_mm", "chatter_freq_hz", "bifurcation"]
    assert isinstance(sld["depth_limit_mm"], np.ndarray)
    assert sld["depth_limit_mm"].dtype == np.float64 and sld["depth_limit_mm"].shape == (400,)
    assert set(sld["bifurcation"]) <= {"hopf", "none"}
    assert result["summary"]["min_limit_mm"] == pytest.approx(sld["depth_limit_mm"].min())
    assert "sld_envelope" in result and "mode" in result["sld_envelope"]
    assert result["message"].startswith("stability (zoa): 400 speeds")


def test_overrides_match_set(cli, source, tmp_path):
    job_file = source / "examples" / "demo.yaml"
    run_cli(cli, ["forces", job_file, "--set", "process.ae=2 mm", "--set", "forces.revolutions=1"],
            tmp_path / "cli")
    # dict, list of assignments, and with_overrides on a loaded job: one job.
    for job in (robomill.Job(job_file, {"process.ae": "2 mm", "forces.revolutions": 1}),
                robomill.Job(job_file, ["process.ae=2 mm", "forces.revolutions=1"]),
                robomill.Job(job_file).with_overrides({"process.ae": "2 mm"})
                                      .with_overrides(["forces.revolutions=1"])):
        assert job.overrides == {"process.ae": "2 mm", "forces.revolutions": "1"}
        assert_same_as_cli(robomill.forces(job), tmp_path / "cli")
    base = robomill.Job(job_file)
    assert base.overrides == {}  # with_overrides made new jobs
    full = robomill.forces(base)["summary"]
    assert full["revolutions"] == 2 and full["mean_N"] != robomill.forces(
        base.with_overrides({"process.ae": "2 mm"}))["summary"]["mean_N"]


def test_list_and_bool_overrides(source):
    job = robomill.Job(source / "examples" / "demo.yaml",
                       {"stability.speeds": {"from": "1000 rpm", "to": "2000 rpm", "count": 3},
                        "stability.modes": "coupled"})
    result = robomill.stability(job)
    assert list(result["sld"]["spindle_rpm"]) == pytest.approx([1000, 1500, 2000])
    assert "sld_envelope" not in result


def test_dict_job_equals_file_job(cli, tmp_path):
    job_file = tmp_path / "demo.json"  # JSON is YAML: the command line reads it as a job
    job_file.write_text(json.dumps(DEMO_DICT, indent=2))
    run_cli(cli, ["stability", job_file], tmp_path / "cli")
    result = robomill.stability(robomill.Job.from_dict(DEMO_DICT))
    cli_summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    del cli_summary["job"]
    summary = dict(result["summary"])
    assert summary.pop("job").endswith("<dict>")
    assert strip_timings(summary) == strip_timings(cli_summary)
    (tmp_path / "cli" / "summary.json").unlink()
    result.pop("summary")
    # The key inputs name the job's source too: a file path, or <dict>.
    cli_inputs = json.loads((tmp_path / "cli" / "inputs.json").read_text())
    inputs = dict(result.pop("inputs"))
    assert inputs.pop("job").endswith("<dict>")
    del cli_inputs["job"]
    assert inputs == cli_inputs
    (tmp_path / "cli" / "inputs.json").unlink()
    assert_same_as_cli(result, tmp_path / "cli")
    # A dict is accepted wherever a job is.
    assert robomill.forces(DEMO_DICT)["summary"]["samples"] == 180


def test_dict_job_paths_are_relative_to_base_dir(source):
    yaml = pytest.importorskip("yaml")  # Debian python3-yaml, when present
    job_file = source / "examples" / "003_kr270_measured_frf.yaml"
    data = yaml.safe_load(job_file.read_text())
    from_dict = robomill.fit_modes(robomill.Job.from_dict(data, base_dir=job_file.parent))
    from_file = robomill.fit_modes(robomill.Job(job_file))
    np.testing.assert_array_equal(from_dict["modes"]["fn_hz"], from_file["modes"]["fn_hz"])
    with pytest.raises(robomill.InputError, match="/nonexistent/"):
        robomill.fit_modes(robomill.Job.from_dict(data, base_dir="/nonexistent"))


def test_validate_lists_sections(source):
    job = robomill.Job(source / "examples" / "demo.yaml")
    assert job.validate() == ["tool", "cutting", "process", "dynamics", "stability"]
    assert job.name.startswith("demo")
    assert "demo.yaml" in repr(job)


def cli_error(cli, *args):
    process = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    return process.returncode, process.stderr.strip()


@pytest.mark.parametrize("bad", [
    "ae_over_diameter", "bad_direction", "bad_law", "empty_file", "inf_value", "map_for_number",
    "missing_teeth", "nan_value", "negative_teeth", "stability_unknown_method",
    "stability_zero_speeds", "string_for_number", "teeth_list", "unknown_key", "unknown_section",
    "unknown_unit", "wrong_dimension", "yaml_syntax", "zero_diameter",
])
def test_invalid_job_raises_the_command_lines_message(cli, source, bad):
    job_file = source / "tests" / "cli" / "bad" / f"{bad}.yaml"
    code, stderr = cli_error(cli, "validate", job_file)
    assert code == 2
    with pytest.raises(robomill.InputError) as error:
        robomill.Job(job_file)
    assert stderr == f"robomill: error: {error.value}"
    assert isinstance(error.value, ValueError) and isinstance(error.value, robomill.Error)
    assert error.value.field and error.value.field in stderr


@pytest.mark.parametrize("command,function,overrides", [
    ("stability", robomill.stability, ["stability.method=zoa", "stability.mode=map"]),
    ("simulate", robomill.simulate, []),
    ("robot", robomill.robot, []),
])
def test_analysis_errors_carry_the_command_lines_message(cli, source, tmp_path, command, function,
                                                         overrides):
    job_file = source / "examples" / "benchmark_1dof_slot.yaml"
    args = [command, job_file, "--out", tmp_path / "out"]
    for o in overrides:
        args += ["--set", o]
    code, stderr = cli_error(cli, *args)
    assert code == 2
    with pytest.raises(robomill.InputError) as error:
        function(robomill.Job(job_file, overrides))
    assert stderr == f"robomill: error: {error.value}"
    assert not (tmp_path / "out").exists()


def test_override_errors(cli, source):
    job_file = source / "examples" / "demo.yaml"
    for assignment in ("process.ae", "process..ae=1", "process.ae="):
        code, stderr = cli_error(cli, "validate", job_file, "--set", assignment)
        assert code == 2
        with pytest.raises(robomill.InputError) as error:
            robomill.Job(job_file, [assignment])
        assert stderr == f"robomill: error: {error.value}"
        assert error.value.field == "--set"
    code, stderr = cli_error(cli, "validate", job_file, "--set", "process.ae=40 mm")
    with pytest.raises(robomill.InputError) as error:
        robomill.Job(job_file, {"process.ae": "40 mm"})
    assert stderr == f"robomill: error: {error.value}"


def test_list_index_overrides_match_set(cli, source, tmp_path):
    """`--set` into a list (dynamics.modes.0.zeta): the same job as the command
    line's, the bracket form the same override, and the same errors."""
    job_file = source / "examples" / "demo.yaml"
    run_cli(cli, ["stability", job_file, "--set", "stability.speeds.count=20",
                  "--set", "dynamics.modes.0.zeta=3 %"], tmp_path / "cli")
    dotted = robomill.stability(robomill.Job(
        job_file, {"stability.speeds.count": 20, "dynamics.modes.0.zeta": "3 %"}))
    assert_same_as_cli(dotted, tmp_path / "cli")
    bracket = robomill.stability(robomill.Job(
        job_file, ["stability.speeds.count=20", "dynamics.modes[0].zeta=3 %"]))
    np.testing.assert_array_equal(dotted["sld"]["depth_limit_mm"], bracket["sld"]["depth_limit_mm"])
    base = robomill.stability(robomill.Job(job_file, {"stability.speeds.count": 20}))
    assert not np.array_equal(base["sld"]["depth_limit_mm"], dotted["sld"]["depth_limit_mm"])
    # A Python list is a whole list, a dict one entry (the length appends).
    modes = [{"direction": "y", "fn": "19.88 Hz", "zeta": "3 %", "k": "3.65e6 N/m"},
             {"direction": "y", "fn": "77.17 Hz", "zeta": "5.15 %", "k": "5.00e6 N/m"},
             {"direction": "x", "fn": "17.8 Hz", "zeta": "1.76 %", "k": "2.31e6 N/m"}]
    whole = robomill.Job(job_file, {"stability.speeds.count": 20, "dynamics.modes": modes,
                                    "dynamics.modes.3": {"direction": "x", "fn": "47.3 Hz",
                                                         "zeta": "0.74 %", "k": 33.6e6}})
    np.testing.assert_array_equal(robomill.stability(whole)["sld"]["depth_limit_mm"],
                                  dotted["sld"]["depth_limit_mm"])
    for assignment in ("dynamics.modes.5.zeta=2%", "dynamics.modes.-1.zeta=2%"):
        code, stderr = cli_error(cli, "validate", job_file, "--set", assignment)
        assert code == 2
        with pytest.raises(robomill.InputError) as error:
            robomill.Job(job_file, [assignment])
        assert stderr == f"robomill: error: {error.value}"
    with pytest.raises(robomill.InputError, match="index 5 is out of range; dynamics.modes has 4 "
                                                  "entries") as error:
        robomill.Job(job_file, {"dynamics.modes.5.zeta": "2 %"})
    assert error.value.field == "dynamics.modes"

def test_missing_file(cli, tmp_path):
    code, stderr = cli_error(cli, "validate", tmp_path / "none.yaml")
    with pytest.raises(robomill.InputError) as error:
        robomill.Job(tmp_path / "none.yaml")
    assert stderr == f"robomill: error: {error.value}"


def test_threads_give_the_same_numbers(source):
    job = robomill.Job(source / "examples" / "benchmark_1dof_005.yaml",
                       {"stability.speeds.count": 16})
    one = robomill.stability(job, threads=1)
    many = robomill.stability(job, threads=4)
    for column in ("spindle_rpm", "depth_limit_mm", "chatter_freq_hz"):
        np.testing.assert_array_equal(one["sld"][column], many["sld"][column])


def test_example_script_runs(source, tmp_path):
    import os
    import sys
    env = dict(os.environ, MPLBACKEND="Agg")
    process = subprocess.run([sys.executable, str(source / "examples" / "python" /
                                                  "stability_study.py")],
                             capture_output=True, text=True, cwd=tmp_path, env=env)
    assert process.returncode == 0, process.stderr
    assert "ae = 12.0 mm" in process.stdout and "rejected: process.ae" in process.stdout


def test_analyses_run_in_parallel_python_threads(source):
    from concurrent.futures import ThreadPoolExecutor
    jobs = [robomill.Job(source / "examples" / "benchmark_1dof_005.yaml",
                         {"stability.speeds.count": 8, "process.ae": f"{ae} mm"})
            for ae in (0.5, 1.0, 1.5, 2.0)]
    alone = [robomill.stability(job, threads=1)["sld"]["depth_limit_mm"] for job in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(lambda job: robomill.stability(job, threads=1), jobs))
    for a, t in zip(alone, together):
        np.testing.assert_array_equal(a, t["sld"]["depth_limit_mm"])


def test_argument_errors(source):
    job = robomill.Job(source / "examples" / "demo.yaml")
    with pytest.raises(robomill.InputError, match="--threads"):
        robomill.forces(job, threads=-3)
    with pytest.raises(robomill.InputError, match="--direction"):
        robomill.identify_cutting(source / "README.md", teeth=2, direction="sideways")
    with pytest.raises(robomill.InputError, match="--kind"):
        robomill.frf(job, kind="velocity")


def test_toolpath_samples_are_arrays_by_program_line(source):
    result = robomill.toolpath(source / "examples" / "toolpath_pocket_gcode.yaml")
    samples = result["samples"]
    assert isinstance(samples["force_peak_N"], np.ndarray)
    assert samples["line"].shape == samples["engagement_deg"].shape
    assert set(samples["motion"]) <= {"rapid", "linear", "arc"}
    summary = result["summary"]
    # The largest force is at the line summary.json names, and it is a sample's.
    worst = int(np.argmax(samples["force_peak_N"]))
    assert summary["max_force_N"] == pytest.approx(samples["force_peak_N"][worst])
    assert summary["max_force_line"] == int(samples["line"][worst])
    # The full slot (line 19 of programs/pocket.nc) engages the half turn.
    slot = samples["line"] == 19
    assert np.median(samples["engagement_deg"][slot]) == pytest.approx(180.0, abs=1.0)
    assert "stock" in result and result["stock"]["z_mm"].min() == pytest.approx(17.0, abs=0.01)


def test_toolpath_with_a_robot_gives_margins_and_postures(source):
    # The pocket on the KR 270 (issue 19): joint angles and margins as float
    # arrays, NaN where a sample is not in the cut; the summary's minimum
    # margin is a sample's.
    result = robomill.toolpath(source / "examples" / "toolpath_robot_pocket.yaml")
    samples = result["samples"]
    margin = samples["margin"]
    assert isinstance(margin, np.ndarray) and margin.dtype == np.float64
    cut = ~np.isnan(margin)
    assert 0 < cut.sum() < margin.size
    assert np.all(samples["chatter"][cut] == (margin[cut] <= 1.0))
    robot = result["summary"]["robot_along_path"]
    assert robot["min_margin"] == pytest.approx(np.nanmin(margin))
    assert robot["min_margin_line"] == int(samples["line"][np.nanargmin(margin)])
    assert samples["q6_deg"].shape == margin.shape and np.all(np.isfinite(samples["q1_deg"]))


def test_toolpath_optimize_caps_the_feeds_and_returns_the_program(source):
    # --optimize from Python: the program written back comes as a text, and
    # the re-run of it keeps every load under robot_path.feed_limits.
    # Sampled every 0.5 mm over 41 speeds, as tests/cli/toolpath.sh does.
    job = robomill.Job(source / "examples" / "toolpath_robot_pocket.yaml",
                       {"toolpath.spacing": "0.5 mm", "stability.speeds.count": 41})
    result = robomill.toolpath(job, optimize=True)
    optimization = result["summary"]["optimization"]
    limits = optimization["feeds"]["limits"]
    assert optimization["feeds"]["lines_changed"] > 0
    assert optimization["after"]["max_force_N"] <= limits["force_max_N"] * (1 + 1e-6)
    assert optimization["after"]["max_deflection_um"] <= limits["deflection_max_um"] * (1 + 1e-6)
    assert "(robomill: feed " in result["program_optimized.nc"]


def test_toolpath_refuses_a_program_by_line_and_word(source):
    job = robomill.Job(source / "examples" / "toolpath_pocket_gcode.yaml",
                       {"toolpath.file": str(source / "tests" / "cli" / "programs" /
                                             "compensated.nc")})
    with pytest.raises(robomill.InputError) as error:
        robomill.toolpath(job)
    assert error.value.line == 8 and "G41" in str(error.value)


def test_listen_spectra_are_arrays_and_match_the_cli(source, cli, tmp_path):
    job = source / "examples" / "listen" / "benchmark_displacement_wav.yaml"
    result = robomill.listen(job)
    spectrum = result["spectrum"]
    assert isinstance(spectrum["freq_hz"], np.ndarray) and spectrum["freq_hz"].dtype == np.float64
    assert set(spectrum["cause"]) >= {"tooth", "chatter"}
    assert [r["verdict"] for r in result["summary"]["recordings"]] == ["stable", "chatter"]
    assert list(result["recordings"]["chatter"]) == ["stable", "chatter"]
    run_cli(cli, ["listen", job], tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert strip_timings(cli)["recordings"] == strip_timings(result["summary"])["recordings"]


def test_analyze_signal_on_a_numpy_array():
    # 4 s of a 2-tooth cut at 6000 rpm: the tooth comb (200 Hz) alone is
    # stable; a strong 731 Hz tone that no harmonic explains is chatter.
    rate = 8000.0
    t = np.arange(int(4 * rate)) / rate
    forced = sum(np.cos(2 * np.pi * 200.0 * k * t) / k for k in range(1, 6))
    noise = 0.01 * np.random.default_rng(1).standard_normal(t.size)
    stable = robomill.analyze_signal(forced + noise, rate, 6000.0, teeth=2)
    assert stable["verdict"] == "stable", stable["reason"]
    chatter = robomill.analyze_signal(forced + noise + 3.0 * np.sin(2 * np.pi * 731.0 * t), rate,
                                      6000.0, teeth=2)
    assert chatter["verdict"] == "chatter", chatter["reason"]
    assert chatter["chatter_freq_hz"] == pytest.approx(731.0, rel=0.005)
    # The verdict's indicators: the tone is nearly all that is off the
    # harmonics, and once-per-revolution samples vary by its share of the cut
    # (4.5 of 4.5 + 0.73).
    assert chatter["chatter_line_fraction"] > 0.95
    assert chatter["once_per_revolution_variance"] == pytest.approx(4.5 / (4.5 + 0.7318), abs=0.02)
    # The verdict asks the line fraction to exceed the threshold: at its own
    # value the cut is stable.
    strict = robomill.analyze_signal(forced + noise + 3.0 * np.sin(2 * np.pi * 731.0 * t), rate,
                                     6000.0, teeth=2, threshold=chatter["chatter_line_fraction"])
    assert strict["verdict"] == "stable", strict["reason"]
    assert chatter["psd"].shape == chatter["freq_hz"].shape
    assert chatter["spectrogram_psd"].shape == (chatter["spectrogram_t_s"].size,
                                               chatter["spectrogram_freq_hz"].size)
    assert chatter["recommended_spindle_rpm"], "no advice"
    with pytest.raises(robomill.InputError):
        robomill.analyze_signal(np.zeros((2, 2)), rate, 6000.0)


def test_atlas_runs_resumes_and_exports_as_the_command_line(cli, source, tmp_path):
    # The library's atlas run (robomill.atlas) writes the store the command
    # line resumes and exports: one job identity, one store format.
    job_file = source / "examples" / "003_kr270_atlas.yaml"
    sets = {"atlas.store": str(tmp_path / "atlas.sqlite"), "atlas.grid.counts": "[3, 2, 1]",
            "atlas.redundancy.count": "2", "atlas.speeds.count": "30"}
    job = robomill.Job(job_file, sets)
    first = robomill.atlas(job, threads=2)
    assert (first["total"], first["computed"], first["already"], first["done"]) == (12, 12, 0, 12)
    again = robomill.atlas(job)
    assert (again["computed"], again["already"], again["done"]) == (0, 12, 12)
    args = [cli, "atlas", str(job_file)]
    for key, value in sets.items():
        args += ["--set", f"{key}={value}"]
    resumed = subprocess.run(args + ["--quiet"], capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    exported = subprocess.run(args + ["--export", str(tmp_path / "cli"), "--quiet"],
                              capture_output=True, text=True)
    assert exported.returncode == 0, exported.stderr
    result = robomill.atlas_export(job)
    assert len(result["atlas"]["item"]) == 12
    assert_same_as_cli(result, tmp_path / "cli")
    # Another job on the same store is refused by name, unless restarted.
    other = job.with_overrides({"atlas.depth_max": "4 mm"})
    with pytest.raises(robomill.InputError, match="atlas.store"):
        robomill.atlas(other)
    assert robomill.atlas(other, restart=True)["computed"] == 12
