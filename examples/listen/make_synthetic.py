#!/usr/bin/env python3
"""The synthetic pair of examples/listen (docs/monitoring.md): the 1-DOF
milling benchmark (examples/benchmark_1dof_005.yaml) at 12 000 rpm, simulated
by `robomill simulate` at 0.8x and 1.25x the depth `robomill stability`
predicts there; the tool's displacement, velocity, radiated sound and the
cutting force written as 16-bit WAV and CSV files with white noise at 20 dB SNR and a 60 Hz mains hum added, as a microphone
or an accelerometer on a real cell would deliver it.

    /usr/bin/python3 examples/listen/make_synthetic.py build/robomill examples/listen

writes displacement_stable.wav, displacement_chatter.wav, sound_chatter.wav,
force_chatter.csv, velocity_stable.csv, displacement_stable_tachometer.wav
(the stable displacement beside a once-per-revolution pulse channel) and
truth.json (the limit, the depths, simulate's verdicts and chatter
frequencies) into the folder. Standard library only; the noise is seeded, so the files are
reproducible.
"""

import csv
import json
import math
import os
import random
import struct
import subprocess
import sys
import tempfile
import wave

HERE = os.path.dirname(os.path.abspath(__file__))
JOB = os.path.join(HERE, "..", "benchmark_1dof_005.yaml")
SPINDLE_RPM = 12000.0
STEPS_PER_TOOTH = 120         # 2 teeth x 200 Hz x 120 = 48 kHz simulation rate
DECIMATE = 3                  # kept every 3rd step: 16 kHz files (a multiple of the
                              # tooth frequency, so harmonics alias onto harmonics)
REVOLUTIONS = 200             # 1 s
SNR_DB = 20.0                 # white noise: 1 % of the signal's power
HUM_HZ = 60.0
HUM_FRACTION = 0.3            # hum amplitude / signal RMS


def run(robomill, *args):
    subprocess.run([robomill, *args, "--quiet"], check=True)


def read_columns(path, *names):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [[float(r[n]) for r in rows] for n in names]


def central_difference(values, dt):
    """d/dt by central differences (one-sided at the ends)."""
    n = len(values)
    out = [0.0] * n
    for i in range(n):
        a, b = max(0, i - 1), min(n - 1, i + 1)
        out[i] = (values[b] - values[a]) / ((b - a) * dt)
    return out


def add_noise_and_hum(t, values, rng):
    """The signal less its mean, with white noise at SNR_DB and a HUM_HZ hum."""
    mean = sum(values) / len(values)
    rms = math.sqrt(sum((v - mean) ** 2 for v in values) / len(values))
    noise_rms = rms * 10.0 ** (-SNR_DB / 20.0)
    hum = HUM_FRACTION * rms * math.sqrt(2.0)
    return [v - mean + rng.gauss(0.0, noise_rms) + hum * math.sin(2 * math.pi * HUM_HZ * ti)
            for ti, v in zip(t, values)]


def write_wav(path, rate, values, full_scale):
    with wave.open(path, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(rate)
        w.writeframes(b"".join(
            struct.pack("<h", max(-32768, min(32767, round(v / full_scale * 32767))))
            for v in values))


def write_files(out, signals, truth):
    """displacement_{stable,chatter}.wav (one full scale for both, so they
    keep their relative levels; the job's `scale` gives metres back),
    sound_chatter.wav, force_chatter.csv (with a time column) and
    velocity_stable.csv (without: the job gives sample_rate)."""
    full_scale_mm = 2.0 * max(abs(v) for s in signals.values() for v in s["displacement"])
    truth["displacement_wav_full_scale_mm"] = full_scale_mm
    for name, s in signals.items():
        write_wav(os.path.join(out, f"displacement_{name}.wav"), s["rate"], s["displacement"],
                  full_scale_mm)
    chatter, stable = signals["chatter"], signals["stable"]
    write_wav(os.path.join(out, "sound_chatter.wav"), chatter["rate"], chatter["sound"],
              2.0 * max(abs(v) for v in chatter["sound"]))
    with open(os.path.join(out, "force_chatter.csv"), "w", newline="") as f:
        f.write("t_s,fx_N\n")
        for ti, v in zip(chatter["t"], chatter["force"]):
            f.write(f"{ti:.8g},{v:.6g}\n")
    with open(os.path.join(out, "velocity_stable.csv"), "w", newline="") as f:
        f.write("# velocity of the tool tip in x (m/s), 16 kHz\nvx_m_per_s\n")
        for v in stable["velocity"]:
            f.write(f"{v:.6g}\n")


def write_tachometer_example(out):
    """displacement_stable_tachometer.wav: displacement_stable.wav's samples
    on channel 1 and a once-per-revolution pulse train on channel 2 (a
    tachometer's: 15 % duty, half full scale, its rising edge at a phase
    nobody chose), for examples/listen/tachometer_wav.yaml."""
    with wave.open(os.path.join(out, "displacement_stable.wav"), "rb") as r:
        rate, frames = r.getframerate(), r.readframes(r.getnframes())
    samples = struct.unpack(f"<{len(frames) // 2}h", frames)
    revolution_s = 60.0 / SPINDLE_RPM
    pulses = [16384 if ((i / rate + 0.000731) / revolution_s) % 1.0 < 0.15 else 0
              for i in range(len(samples))]
    with wave.open(os.path.join(out, "displacement_stable_tachometer.wav"), "wb") as w:
        w.setnchannels(2)
        w.setsampwidth(2)
        w.setframerate(rate)
        w.writeframes(b"".join(struct.pack("<hh", a, b) for a, b in zip(samples, pulses)))


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: make_synthetic.py ROBOMILL OUTDIR")
    robomill, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    rng = random.Random(22)
    with tempfile.TemporaryDirectory() as work:
        run(robomill, "stability", JOB, "--set",
            f"stability.speeds={{from: {SPINDLE_RPM} rpm, to: {SPINDLE_RPM} rpm, count: 1}}",
            "--out", os.path.join(work, "sld"))
        (limit_mm,), (predicted_hz,) = read_columns(os.path.join(work, "sld", "sld.csv"),
                                                    "depth_limit_mm", "chatter_freq_hz")
        truth = {"job": "examples/benchmark_1dof_005.yaml", "spindle_rpm": SPINDLE_RPM,
                 "depth_limit_mm": limit_mm, "predicted_chatter_freq_hz": predicted_hz,
                 "snr_db": SNR_DB, "hum_hz": HUM_HZ, "cuts": {}}
        signals = {}
        for name, factor in (("stable", 0.8), ("chatter", 1.25)):
            depth = factor * limit_mm
            folder = os.path.join(work, name)
            run(robomill, "simulate", JOB, "--set", f"process.spindle={SPINDLE_RPM} rpm",
                "--set", f"process.ap={depth} mm", "--set",
                f"simulation={{revolutions: {REVOLUTIONS}, steps_per_tooth: {STEPS_PER_TOOTH}}}",
                "--out", folder)
            t, x, fx = read_columns(os.path.join(folder, "timeseries.csv"), "t_s", "x_mm", "fx_N")
            with open(os.path.join(folder, "summary.json")) as f:
                summary = json.load(f)
            t, x, fx = t[::DECIMATE], x[::DECIMATE], fx[::DECIMATE]
            rate = round(1.0 / (t[1] - t[0]))
            dt = 1.0 / rate
            # What each sensor sees: the tool displacement (mm), its velocity
            # (m/s, a laser vibrometer), the radiated sound (modelled as the
            # surface acceleration, m/s^2: far-field pressure of a compact
            # vibrating source is proportional to it; uncalibrated) and the
            # cutting force (N, a dynamometer).
            velocity = central_difference([v * 1e-3 for v in x], dt)
            sound = central_difference(velocity, dt)
            signals[name] = {
                "rate": rate, "t": t,
                "displacement": add_noise_and_hum(t, x, rng),
                "velocity": add_noise_and_hum(t, velocity, rng),
                "sound": add_noise_and_hum(t, sound, rng),
                "force": add_noise_and_hum(t, fx, rng)}
            truth["cuts"][name] = {"depth_mm": depth, "depth_factor": factor,
                                   "simulate_chatter": summary["chatter"],
                                   "simulate_chatter_freq_hz": summary["chatter_freq_hz"],
                                   "sample_rate_hz": rate, "samples": len(t)}
        write_files(out, signals, truth)
        write_tachometer_example(out)
        with open(os.path.join(out, "truth.json"), "w") as f:
            json.dump(truth, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
