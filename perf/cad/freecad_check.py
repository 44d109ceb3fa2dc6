# Run by perf/cad/freecad_check.sh under FreeCAD's command line (freecadcmd): opens every NAME.step and NAME.igs
# in $FIRE_CAD_DIR with FreeCAD's own reader and prints, per file, whether the shape is valid, its faces against
# the patches bench_cad wrote (bench.txt in the same folder: one face per patch), its shells and solids.
import os
import re

import FreeCAD
import Part

print("freecad %s" % ".".join(FreeCAD.Version()[:3]))
folder = os.environ["FIRE_CAD_DIR"]
patches = {}
with open(os.path.join(folder, "bench.txt")) as bench:
    for line in bench:
        m = re.match(r"(\S+): network .* patches (\d+) ", line)
        if m:
            patches[m.group(1)] = int(m.group(2))
failed = 0
for name in sorted(patches):
    for ext in (".step", ".igs"):
        path = os.path.join(folder, name + ext)
        shape = Part.read(path)
        valid = shape.isValid()
        one_per_patch = len(shape.Faces) == patches[name]
        box = shape.BoundBox
        print("freecad %-14s valid %-3s  %5d faces for %5d patches (one per patch: %s)  %d shells  %d solids  "
              "%.1f x %.1f x %.1f mm" % (name + ext, "yes" if valid else "NO", len(shape.Faces), patches[name],
                                         "yes" if one_per_patch else "NO", len(shape.Shells), len(shape.Solids),
                                         box.XLength, box.YLength, box.ZLength))
        failed += not (valid and one_per_patch)
print("freecad: %d of %d files valid with one face per patch" % (2 * len(patches) - failed, 2 * len(patches)))
os._exit(1 if failed else 0)
