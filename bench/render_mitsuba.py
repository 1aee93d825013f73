"""Renders every sensor of a Mitsuba 3 scene (as `visgate export mitsuba` writes it) to
OUT_DIR/SENSOR.exr, linear RGB; prints the time of each. Usage: SCENE.xml OUT_DIR [SEED]."""
import os
import sys
import time

import mitsuba as mi


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    xml, out = sys.argv[1], sys.argv[2]
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    variant = "scalar_rgb"
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        variant = "llvm_ad_rgb"
    mi.set_variant(variant)
    scene = mi.load_file(xml)
    os.makedirs(out, exist_ok=True)
    for i, sensor in enumerate(scene.sensors()):
        name = sensor.id() or f"sensor{i}"
        t = time.time()
        img = mi.render(scene, sensor=i, seed=seed)
        path = os.path.join(out, f"{name}.exr")
        mi.Bitmap(img).write(path)
        print(f"{variant}: {path} in {time.time() - t:.1f} s")


if __name__ == "__main__":
    main()
