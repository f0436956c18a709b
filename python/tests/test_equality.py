"""Python results equal the command line's, to the last written digit, for
the same job and overrides: every analysis on the example jobs."""

import pytest

import robomill

from equality import assert_same_as_cli, run_cli

ADVISE_FAST = ["advise.speeds={from: 1000 rpm, to: 12000 rpm, count: 23}", "advise.refine=4",
               "advise.redundancy.angles={from: -60 deg, to: 30 deg, count: 4}"]
OPTIMIZE_FAST = ["optimize.budget=40", "optimize.local_budget=20",
                 "optimize.landscape={x: 3, y: 2, theta: [0, 60]}"]

# (command, Python function, example job, --set overrides)
CASES = [
    ("forces", robomill.forces, "demo.yaml", []),
    ("forces", robomill.forces, "002_kr270_fractional_law.yaml", ["forces.revolutions=1"]),
    ("stability", robomill.stability, "demo.yaml", ["stability.speeds.count=40"]),
    ("stability", robomill.stability, "benchmark_1dof_005.yaml", ["stability.speeds.count=12"]),
    ("stability", robomill.stability, "benchmark_1dof_slot.yaml",
     ["stability.mode=map", "stability.speeds.count=4", "stability.depths=5"]),
    ("stability", robomill.stability, "003_kr270_process_damping.yaml",
     ["stability.speeds.count=30"]),
    ("stability", robomill.stability, "003_kr270_measured_frf.yaml",
     ["stability.speeds.count=20"]),
    ("stability", robomill.stability, "000_kr600_multipoint.yaml",
     ["stability.speeds={from: 7200 rpm, to: 8200 rpm, count: 2}"]),
    ("fit-modes", robomill.fit_modes, "003_kr270_measured_frf.yaml", []),
    ("simulate", robomill.simulate, "002_case_b_1dof.yaml", ["simulation.duration=1.2"]),
    ("simulate", robomill.simulate, "002_case_c_2dof.yaml", ["simulation.duration=1.2"]),
    ("robot", robomill.robot, "000_kr600_multipoint.yaml", []),
    ("robot", robomill.robot, "004_kr300_pose_optimization.yaml", ["robot.map.counts=[4,3,1]"]),
    ("deflection", robomill.deflection, "000_kr600_multipoint.yaml", []),
    ("optimize", robomill.optimize, "004_kr300_pose_optimization.yaml", OPTIMIZE_FAST),
    ("advise", robomill.advise, "003_kr270_cutting_advice.yaml", ADVISE_FAST),
    # With uncertainty: (issue 33): the band's lobes_quantiles and
    # chatter_probability, the robust advice's advice_map_robust, as arrays.
    ("stability", robomill.stability, "uncertainty_stability.yaml",
     ["uncertainty.samples=16", "stability.speeds.count=15", "stability.depths=7"]),
    ("advise", robomill.advise, "uncertainty_stability.yaml",
     ["uncertainty.samples=16", "advise.speeds={from: 300 rpm, to: 6000 rpm, count: 12}",
      "advise.refine=2"]),
    # Learning from tests (issue 35): the posterior samples, both bands, the
    # experiments and the next test, on a coarse grid with few samples.
    ("learn", robomill.learn, "learn/anchor_tool.yaml",
     ["learn.samples=200", "uncertainty.samples=64", "stability.speeds.count=16",
      "stability.depths=8"]),
    ("surface", robomill.surface, "001_case_5_surface.yaml",
     ["surface.grid=[100, 100]", "surface.grid_rule=false"]),
    ("toolpath", robomill.toolpath, "toolpath_pocket_gcode.yaml", []),
    ("toolpath", robomill.toolpath, "toolpath_ball_5axis_apt.yaml", ["stock.resolution=0.5 mm"]),
    # The robot along a program with uncertainty: (issue 33): samples with
    # p_chatter, p_chatter_se and the band of the stable depth.
    # Sampled every 1 mm (257 samples, not the example's 1960): the same
    # outputs compared, in a fifth of the time.
    ("toolpath", robomill.toolpath, "uncertainty_toolpath.yaml",
     ["uncertainty.samples=4", "toolpath.spacing=1 mm"]),
]


@pytest.mark.parametrize("command,function,example,overrides", CASES,
                         ids=[f"{c[0]}-{c[2]}" for c in CASES])
def test_analysis_equals_command_line(cli, source, tmp_path, command, function, example,
                                      overrides):
    job_file = source / "examples" / example
    args = [command, job_file]
    for assignment in overrides:
        args += ["--set", assignment]
    run_cli(cli, args, tmp_path / "cli")
    job = robomill.Job(job_file, overrides)
    result = function(job, out=tmp_path / "py")
    assert_same_as_cli(result, tmp_path / "cli", tmp_path / "py")


@pytest.mark.parametrize("options,args", [
    ({}, []),
    ({"format": "csv", "kind": "mobility", "from_": "10", "to": "100", "step": "1"},
     ["--format", "csv", "--kind", "mobility", "--from", "10", "--to", "100", "--step", "1"]),
    ({"format": "uff58b", "from_": "10", "to": "100", "step": "0.5", "noise": 0.02, "seed": 3},
     ["--format", "uff58b", "--from", "10", "--to", "100", "--step", "0.5", "--noise", "0.02",
      "--seed", "3"]),
    ({"spacing": "log", "from_": "10 Hz", "to": "6 kHz", "points": 300},
     ["--spacing", "log", "--from", "10 Hz", "--to", "6 kHz", "--points", "300"]),
], ids=["uff58", "csv-mobility", "uff58b-noise", "log"])
def test_frf_equals_command_line(cli, source, tmp_path, options, args):
    job_file = source / "examples" / "003_kr270_measured_frf.yaml"
    run_cli(cli, ["frf", job_file, *args], tmp_path / "cli")
    result = robomill.frf(robomill.Job(job_file), out=tmp_path / "py", **options)
    assert_same_as_cli(result, tmp_path / "cli", tmp_path / "py")


def test_identify_cutting_equals_command_line(cli, source, tmp_path):
    # Mean forces from robomill.forces at five feeds, as tests/cli/identify_cutting.sh.
    job = robomill.Job.from_text(
        "tool: {type: flat, diameter: 8 mm, teeth: 2, helix: 30 deg, overhang: 25 mm}\n"
        "cutting: {law: linear, Ktc: 1661.8 N/mm^2, Krc: 1240.8 N/mm^2, Kac: 19.1 N/mm^2,\n"
        "          Kte: 7.1 N/mm, Kre: 15.9 N/mm, Kae: 2.3 N/mm}\n"
        "process: {spindle: 5000 rpm, feed_per_tooth: 0.02 mm, ap: 1 mm, ae: 8 mm}\n"
        "forces: {revolutions: 1, steps_per_tooth: 400, axial_elements: 50}\n")
    lines = ["feed_per_tooth_mm,fx_N,fy_N,fz_N"]
    for fz in (0.02, 0.04, 0.06, 0.08, 0.10):
        mean = robomill.forces(job.with_overrides({"process.feed_per_tooth": fz}))["summary"]["mean_N"]
        lines.append(f"{fz},{mean['x']!r},{mean['y']!r},{mean['z']!r}")
    data = tmp_path / "tests.csv"
    data.write_text("\n".join(lines) + "\n")
    run_cli(cli, ["identify-cutting", data, "--teeth", "2", "--ap", "1 mm"], tmp_path / "cli")
    result = robomill.identify_cutting(data, teeth=2, ap="1 mm", out=tmp_path / "py")
    assert_same_as_cli(result, tmp_path / "cli", tmp_path / "py")
    assert abs(result["summary"]["coefficients"]["Ktc_N_per_mm2"] / 1661.8 - 1) < 0.01


def test_identify_stiffness_equals_command_line(cli, source, tmp_path):
    job_file = source / "examples" / "000_kr600_multipoint.yaml"
    tests = source / "examples" / "data" / "000_kr600_loading_tests.csv"
    plan = source / "examples" / "data" / "000_kr600_loading_plan.csv"
    run_cli(cli, ["identify-stiffness", tests, "--job", job_file], tmp_path / "cli")
    result = robomill.identify_stiffness(tests, robomill.Job(job_file), out=tmp_path / "py")
    assert_same_as_cli(result, tmp_path / "cli", tmp_path / "py")

    run_cli(cli, ["identify-stiffness", plan, "--job", job_file, "--synthesize", "--noise", "0.01",
                  "--seed", "7"], tmp_path / "cli-syn")
    result = robomill.identify_stiffness(plan, job_file, synthesize=True, noise=0.01, seed=7)
    assert "summary" not in result
    assert_same_as_cli(result, tmp_path / "cli-syn")
