# Run by tests/cli/mdd_blender.sh inside `blender -b`: imports the gale module built for
# Debian's python3 (Blender's Python is the same 3.11) and evaluates an expression.
import sys
sys.path.insert(0, sys.argv[sys.argv.index("--") + 1])
import gale, numpy as np, bpy
e = gale.compile(source="$P * 2 + [0, 0, $t]")
print("GALE", gale.__version__, sys.version.split()[0], e.eval(np.array([[1.0, 2.0, 3.0]]), t=0.5, precision="double").tolist())
