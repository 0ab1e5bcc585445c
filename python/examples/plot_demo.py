"""Plot a demo run: spectra, BRDF and the tile, saved as PNG.

Run it from the repository root after `inksim run configs/demo.toml`:

    python python/examples/plot_demo.py                    # runs/demo/demo.h5
    python python/examples/plot_demo.py path/to/result.h5 --out plots/

Written notebook-style: each `# %%` block is a cell (VS Code, Jupytext and
Spyder run them one by one); the PNGs go next to the result unless --out
says where.
"""

# %% Setup
import argparse
import os

import matplotlib

matplotlib.use("Agg")  # files only; drop this line in a notebook

import inksim  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("result", nargs="?", default="runs/demo/demo.h5",
                    help="result file (default: runs/demo/demo.h5)")
parser.add_argument("--out", default=None, help="folder for the PNGs (default: beside the result)")
parser.add_argument("--wavelength", type=float, default=None,
                    help="wavelength of the BRDF plot, nm (default: the middle one)")
args = parser.parse_args()
if not os.path.exists(args.result):
    parser.exit(1, f"{args.result}: not found; run `inksim run configs/demo.toml` first "
                   "or pass a result file\n")
out = args.out or os.path.dirname(os.path.abspath(args.result))
os.makedirs(out, exist_ok=True)
stem = os.path.splitext(os.path.basename(args.result))[0]

# %% Open the result: every part is labelled xarray data
r = inksim.open_result(args.result)
print(r)
print(r.spectra)
print("colour under a white sky (CIELAB, per viewing angle):")
print(r.colours["natural_lab"].to_pandas())

# %% Energy balance of every solve
s = r.solves
print("worst |R + T + A - 1| over the solves:",
      float(abs(s.total_reflectance + s.total_transmittance + s.absorption - 1).max()))

# %% Spectra: R, T, A against wavelength, one line per angle of incidence
fig = inksim.plot_spectra(r)
path = os.path.join(out, f"{stem}-spectra.png")
fig.savefig(path, dpi=120)
print("wrote", path)

# %% BRDF: in-plane curve and polar map
fig = inksim.plot_brdf(r, wavelength=args.wavelength)
path = os.path.join(out, f"{stem}-brdf.png")
fig.savefig(path, dpi=120)
print("wrote", path)

# %% The tile stored in the file
fig = inksim.show_tile(r)
path = os.path.join(out, f"{stem}-tile.png")
fig.savefig(path, dpi=120)
print("wrote", path)
