"""Reads a 3MF file with lib3mf (3MF Consortium) in strict mode and prints, one line:
objects, triangles, unit, warnings, and the names of invalid objects (none if valid)."""
import sys

import lib3mf

model = lib3mf.get_wrapper().CreateModel()
reader = model.QueryReader("3mf")
reader.SetStrictModeActive(True)
reader.ReadFromFile(sys.argv[1])
objects, triangles, invalid = 0, 0, []
it = model.GetMeshObjects()
while it.MoveNext():
    o = it.GetCurrentMeshObject()
    objects += 1
    triangles += o.GetTriangleCount()
    if not o.IsValid():
        invalid.append(o.GetName())
warnings = [reader.GetWarning(i)[1] for i in range(reader.GetWarningCount())]
print(f"objects {objects} triangles {triangles} unit {model.GetUnit()} warnings {len(warnings)} invalid {invalid} {warnings}")
