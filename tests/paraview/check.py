"""Opens diefill's outputs with ParaView's own readers, as docs/user-guide.md tells a user to,
and checks what ParaView shows against what the files hold.  Run with pvpython (ParaView's
Python); each check prints 'PASS: ...' or 'FAIL: ...' lines and the exit status is the number
of failures (0: all passed).

    pvpython check.py particles CASE EXPECTED.json LABEL
        dem/particles.xdmf with the Xdmf Reader and the Xdmf3 reader: the output times (those
        of particles.series that hold particles), the particle count of each, the seven arrays with their
        components, the positions' bounds, the radius and id ranges; then the user guide's
        Glyph (sphere, scale array radius, factor 2) at the last time: its z extent is that of
        the particles' spheres (z - r to z + r).  EXPECTED.json: expected.py's.
    pvpython check.py air CASE TYPE NCELLS OUT.json LABEL
        case.foam with the OpenFOAM reader (TYPE: reconstructed or decomposed): the last time's
        internal mesh has NCELLS cells and the fields U, p, alpha.air (0 < alpha.air <= 1, below
        1 somewhere: particles are in it); their sorted values go to OUT.json (to compare two
        reads of one case).
    pvpython check.py vtk FILE EXPECTED.json LABEL
        a legacy VTK file (fillDensity.vtk) with the legacy VTK reader: dimensions, origin,
        spacing and every cell array's values in VTK's order (x fastest)."""
import json
import sys

from paraview import servermanager
from paraview.simple import (Glyph, LegacyVTKReader, MergeBlocks, OpenFOAMReader, XDMFReader,
                             Xdmf3ReaderS)
from vtk.util.numpy_support import vtk_to_numpy

failures = 0


def report(ok, what):
    global failures
    print(("PASS: " if ok else "FAIL: ") + what, flush=True)
    failures += 0 if ok else 1


def close(a, b, tol):
    return len(a) == len(b) and all(abs(x - y) <= tol for x, y in zip(a, b))


COMPONENTS = {"velocity": 3, "omega": 3, "force": 3, "radius": 1, "mass": 1, "id": 1, "material": 1}


def particles(case, expected_file, label):
    expected = json.load(open(expected_file))["entries"]
    path = f"{case}/dem/particles.xdmf"
    shown = [e for e in expected if e["count"] > 0]      # what the index lists
    last = max(shown, key=lambda e: e["time"])
    for name, make in (("Xdmf Reader", lambda: XDMFReader(FileNames=[path])),
                       ("Xdmf3 reader", lambda: Xdmf3ReaderS(FileName=[path]))):
        reader = make()
        reader.UpdatePipelineInformation()
        times = list(reader.TimestepValues)
        report(close(times, [e["time"] for e in shown], 1e-9),
               f"{label}, {name}: the output times {times} are those of particles.series' {len(expected)} outputs"
               f" that hold particles")
        wrong = []
        for time in times:      # as a user steps through them
            e = next((e for e in expected if abs(e["time"] - time) <= 1e-9), None)
            if e is None:
                wrong.append(f"t = {time}: not in particles.series")
                continue
            reader.UpdatePipeline(time)
            data = servermanager.Fetch(reader)
            n = data.GetNumberOfPoints()
            if n != e["count"]:
                wrong.append(f"t = {e['time']}: {n} points, expected {e['count']}")
                continue
            pd = data.GetPointData()
            arrays = {pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}
            if arrays != COMPONENTS:
                wrong.append(f"t = {e['time']}: arrays {arrays}, expected {COMPONENTS}")
                continue
            b = data.GetBounds()
            if not (close(b[0::2], e["positionMin"], 0) and close(b[1::2], e["positionMax"], 0)):
                wrong.append(f"t = {e['time']}: bounds {b}, positions from {e['positionMin']} to {e['positionMax']}")
            if not close(pd.GetArray("radius").GetRange(), e["radiusRange"], 0):
                wrong.append(f"t = {e['time']}: radius {pd.GetArray('radius').GetRange()}, expected {e['radiusRange']}")
            ids = vtk_to_numpy(pd.GetArray("id"))
            if [int(ids.min()), int(ids.max())] != e["idRange"] or len(set(ids.tolist())) != e["distinctIds"]:
                wrong.append(f"t = {e['time']}: ids {ids.min()}..{ids.max()} ({len(set(ids.tolist()))} distinct), "
                             f"expected {e['idRange']} ({e['distinctIds']})")
        report(not wrong, f"{label}, {name}: every time's particle count, arrays (components), bounds, radii and ids"
                          f" as in the HDF5 files" + ("" if not wrong else
                          ": " + "; ".join(wrong[:4])))
    # The user guide's picture: spheres of the particles' own size
    reader = XDMFReader(FileNames=[path])
    glyph = Glyph(Input=reader, GlyphType="Sphere")
    glyph.ScaleArray = ["POINTS", "radius"]
    glyph.ScaleFactor = 2.0
    glyph.GlyphMode = "All Points"
    glyph.UpdatePipeline(last["time"])
    z = glyph.GetDataInformation().GetBounds()[4:6]
    report(close(z, last["sphereZ"], 1e-7),
           f"{label}: Glyph (sphere, scale array radius, factor 2) at t = {last['time']}: z from {z[0]:.7g} to "
           f"{z[1]:.7g} m, the particles' spheres {last['sphereZ'][0]:.7g} to {last['sphereZ'][1]:.7g} m")


def air(case, case_type, ncells, out, label):
    reader = OpenFOAMReader(FileName=f"{case}/case.foam")
    reader.CaseType = {"reconstructed": "Reconstructed Case", "decomposed": "Decomposed Case"}[case_type]
    reader.MeshRegions = ["internalMesh"]
    reader.UpdatePipelineInformation()
    times = list(reader.TimestepValues)
    report(bool(times) and times[-1] > 0, f"{label}: the OpenFOAM reader ({case_type} case) finds the times {times}")
    if not times:
        return
    merged = MergeBlocks(Input=reader)
    merged.UpdatePipeline(times[-1])
    data = servermanager.Fetch(merged)
    cd = data.GetCellData()
    names = {cd.GetArrayName(i) for i in range(cd.GetNumberOfArrays())}
    report(data.GetNumberOfCells() == ncells and {"U", "p", "alpha.air"} <= names,
           f"{label}: at t = {times[-1]}: {data.GetNumberOfCells()} cells (expected {ncells}), fields {sorted(names)}")
    if not {"U", "p", "alpha.air"} <= names:
        return
    alpha = vtk_to_numpy(cd.GetArray("alpha.air"))
    report(alpha.min() > 0 and alpha.max() <= 1 and alpha.min() < 1,
           f"{label}: alpha.air from {alpha.min():.4g} to {alpha.max():.4g} (the particles' share in the cells)")
    json.dump({k: sorted(vtk_to_numpy(cd.GetArray(k)).ravel().tolist()) for k in ("U", "p", "alpha.air")},
              open(out, "w"))


def vtk_file(path, expected_file, label):
    expected = json.load(open(expected_file))
    reader = LegacyVTKReader(FileNames=[path])
    reader.UpdatePipeline()
    data = servermanager.Fetch(reader)
    report(list(data.GetDimensions()) == expected["dimensions"]
           and close(data.GetOrigin(), expected["origin"], 1e-12) and close(data.GetSpacing(), expected["spacing"], 1e-12),
           f"{label}: dimensions {data.GetDimensions()}, origin {data.GetOrigin()}, spacing {data.GetSpacing()}")
    cd = data.GetCellData()
    for name, values in expected["arrays"].items():
        array = cd.GetArray(name)
        got = vtk_to_numpy(array).tolist() if array is not None else []
        report(close(got, values, 1e-6 * max(1.0, max(abs(v) for v in values))),
               f"{label}: cell array {name}: {len(got)} values in VTK's order as written ({len(values)})")


if __name__ == "__main__":
    mode, args = sys.argv[1], sys.argv[2:]
    if mode == "particles":
        particles(*args)
    elif mode == "air":
        air(args[0], args[1], int(args[2]), args[3], args[4])
    elif mode == "vtk":
        vtk_file(*args)
    else:
        sys.exit(f"check.py: unknown mode '{mode}' (particles, air or vtk)")
    sys.exit(min(failures, 100))
