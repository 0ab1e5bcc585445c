#!/usr/bin/env python3
"""The multi-angle target of an effect match example, made by inksim itself from a known recipe.

    python3 scripts/make_match_effect_target.py configs/match-pearl.toml 0.03 132

takes the match file's inline base paint ([base.paint] …), sets its one flake layer's volume
fraction (and, when given, its coated flakes' coating thickness in nm) to the known recipe, runs
`inksim run` on that paint (the binary: $INKSIM_BIN, else `inksim` on PATH) in a temporary
folder, reads the multi-angle CIELAB it wrote (paint/multiangle/lab, under the paint's illuminant
and observer) and prints the target's `colour = [...]` lines for the geometries the match file
states, rounded to 0.01 as an instrument reports them. Needs h5py.
"""

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py


def base_paint(match_text: str) -> str:
    """The match file's [base.paint…] tables as a paint file's [paint…] tables."""
    out, inside = [], False
    for line in match_text.splitlines():
        header = re.match(r"^\s*(\[\[?)\s*([A-Za-z0-9_.]+)\s*(\]\]?)", line)
        if header:
            name = header.group(2)
            inside = name == "base.paint" or name.startswith("base.paint.")
            if inside:
                line = f"{header.group(1)}{name[len('base.'):]}{header.group(3)}"
        if inside:
            out.append(line)
    if not out:
        sys.exit("no inline [base.paint] in the match file")
    return "\n".join(out) + "\n"


def set_once(text: str, pattern: str, value: str) -> str:
    new, n = re.subn(pattern, lambda m: m.group(1) + value, text)
    if n != 1:
        sys.exit(f"expected exactly one match of {pattern!r}, found {n}")
    return new


def main() -> None:
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    match_file = Path(sys.argv[1])
    text = match_file.read_text()
    paint = base_paint(text)
    paint = set_once(paint, r"(?m)^(volume_fraction\s*=\s*)[0-9.eE+-]+", sys.argv[2])
    if len(sys.argv) == 4:
        paint = set_once(paint, r"(coating\s*=\s*\{[^}]*?\}\s*,\s*thickness_nm\s*=\s*)[0-9.eE+-]+",
                         sys.argv[3])
    binary = os.environ.get("INKSIM_BIN", "inksim")
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "known.toml"
        path.write_text(paint + '\n[output]\nname = "known"\n')
        subprocess.run([binary, "run", str(path), "--output-dir", d], check=True,
                       capture_output=True, text=True)
        with h5py.File(Path(d) / "known.h5", "r") as f:
            g = f["paint/multiangle"]
            ill, asp, lab = g["illumination_deg"][()], g["aspecular_deg"][()], g["lab"][()]
    wanted = [(float(a), float(b)) for a, b in re.findall(
        r"illumination_deg\s*=\s*([0-9.+-]+)\s*,\s*aspecular_deg\s*=\s*([0-9.+-]+)", text)]
    print("colour = [")
    for i, a, l in zip(ill, asp, lab):
        if not wanted or (float(i), float(a)) in wanted:
            print(f"    {{ illumination_deg = {i:.1f}, aspecular_deg = {a:.1f}, "
                  f"lab = [{l[0]:.2f}, {l[1]:.2f}, {l[2]:.2f}] }},")
    print("]")


if __name__ == "__main__":
    main()
