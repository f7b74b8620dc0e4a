#!/usr/bin/env python3
"""Layers point down: no header under include/nhdyn/ includes one from a layer above its own.
Usage: check_layers.py SOURCE_DIR. Prints each offending include and exits 1 if there is one.

The layers, lowest first (a header may include its own layer and any below it):"""
import pathlib
import re
import sys

LAYERS = [
    ["config.hpp", "errors.hpp", "version.hpp"],  # files at the top of include/nhdyn/
    ["scalar"],        # number types and their traits
    ["detail"],        # small buffers, factorisations: no model knowledge
    ["model"],         # chains, trees, their validated constants (DH and tree kernels' data)
    ["spatial"],       # spatial algebra
    ["functional"],    # values between stages, composition
    ["kinematics"],
    ["dynamics"],      # rne, CRBA, forward dynamics; no constraint knowledge
    ["constraints"],   # Pfaffian constraints and the nonholonomic stages
    ["robots"],        # a model with its constraint; the presets
    ["analysis"],      # linearisation, bounds
    ["io"],            # files
    ["simulation"],
    ["robot_dynamics.hpp"],  # a loaded robot's double dynamics, compiled once in nhdyn::compiled
    ["nhdyn.hpp"],     # everything
]
__doc__ += "\n    " + " < ".join("/".join(l) for l in LAYERS)


def layer_of(rel: pathlib.PurePosixPath) -> int:
    key = rel.parts[0] if len(rel.parts) > 1 else rel.name
    for i, names in enumerate(LAYERS):
        if key in names:
            return i
    raise SystemExit(f"check_layers: {rel}: not in any layer (add it to LAYERS in {__file__})")


def main() -> int:
    root = pathlib.Path(sys.argv[1]) / "include" / "nhdyn"
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
    bad = 0
    headers = sorted(root.rglob("*.hpp"))
    for h in headers:
        rel = pathlib.PurePosixPath(h.relative_to(root).as_posix())
        own = layer_of(rel)
        for target in include.findall(h.read_text(encoding="utf-8")):
            t = (h.parent / target).resolve()
            try:
                trel = pathlib.PurePosixPath(t.relative_to(root.resolve()).as_posix())
            except ValueError:
                continue  # outside nhdyn (a system header in quotes)
            if layer_of(trel) > own:
                print(f"{rel}: includes {trel}, a layer above ({'/'.join(LAYERS[layer_of(trel)])} > "
                      f"{'/'.join(LAYERS[own])})")
                bad += 1
    print(f"check_layers: {len(headers)} headers, {bad} upward include(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
