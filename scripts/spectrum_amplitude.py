"""Where the nonlinear run parts from the linear picture: the double defect rod of the paper's
woodpile under 1 N (pipeline/spectrum/spectrum_measured.toml's chain), struck ever harder.

For each impact velocity V, runs `woodpile spectrum --measure` and prints the amplitude (V over
the precompression's own velocity scale c0 δ0) and the largest difference of |t| between the
run and the linear picture over the frequencies the run resolves. A physical scene's times are
in the model's scaled unit L/V, which grows as V^(-1/5): t_end, sample_every and dt are scaled
with it so that every run covers the same 14.6 ms at the same resolution.

    python3 scripts/spectrum_amplitude.py [path/to/woodpile]
"""
import json
import pathlib
import subprocess
import sys
import tempfile

SCENE = """
[chain]
sites = [-400, 400]
precompression = 1.0
[physical]
material = {{ youngs_modulus = 72e9, poisson_ratio = 0.17, density = 2200.0 }}
rod = {{ length = 0.020, diameter = 0.005 }}
velocity = {velocity}
[impulse]
site = -30
[[defect]]
site = -4
rod = {{ length = 0.040 }}
[[defect]]
site = 3
rod = {{ length = 0.040 }}
[run]
t_end = {t_end}
sample_every = {sample_every}
method = "rkn6-contact"
dt = {dt}
"""

# At V = 1e-6 m/s: 80 time units of 165 µs, sampled every 0.05, stepped by 0.005.
REFERENCE_V, T_END, SAMPLE, DT = 1e-6, 80.0, 0.05, 0.005
VELOCITIES = [1e-6, 1e-5, 1e-4, 3e-4, 1e-3, 2e-3, 3e-3, 5e-3, 1e-2, 3e-2]


PARTED = 0.1


def measured(woodpile, folder, v):
    """The `measured` block of the run at impact velocity v."""
    # Scaled time runs as V^(1/5) of SI time: the same SI window at every V.
    scale = (v / REFERENCE_V) ** 0.2
    path = pathlib.Path(folder) / "scene.toml"
    path.write_text(SCENE.format(velocity=v, t_end=T_END * scale,
                                 sample_every=SAMPLE * scale, dt=DT * scale))
    out = subprocess.run([woodpile, "spectrum", str(path), "--measure"],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)["measured"]


def main():
    woodpile = sys.argv[1] if len(sys.argv) > 1 else "target/release/woodpile"
    print("| V (m/s) | amplitude V/(c0 δ0) | frequencies resolved | largest difference of abs(t) |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        rows = [(v, measured(woodpile, folder, v)) for v in VELOCITIES]
        for v, m in rows:
            print(f"| {v:g} | {m['amplitude']:.3g} | {m['points']} | {m['departure']:.3g} |")
        # Bisect (in log V) for the first V whose |t| differs by PARTED.
        below = max(v for v, m in rows if m["departure"] < PARTED)
        above = min(v for v, m in rows if m["departure"] >= PARTED)
        while above / below > 1.01:
            middle = (above * below) ** 0.5
            if measured(woodpile, folder, middle)["departure"] < PARTED:
                below = middle
            else:
                above = middle
        m = measured(woodpile, folder, above)
        print(f"\n|t| first differs by {PARTED} at V = {above:.3g} m/s, "
              f"amplitude {m['amplitude']:.3g}.")


if __name__ == "__main__":
    main()
