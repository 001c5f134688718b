#!/usr/bin/python3
"""Checks that other tools read the files hexrefine writes.

usage: check_external_readers.py HEXREFINE SHARED_DIR TEMP_DIR

Converts the shared meshes and a generated jittered brick to every format hexrefine writes
(.mesh, .vtk ASCII and BINARY, .vtu appended binary, zlib and ASCII, .msh text and binary, .e,
.inp) with
`hexrefine convert`, then checks:
  - meshio reads every file with the right hex count;
  - VTK (python3-vtk9) reads the .vtk, .vtu and .e files with the right hex count;
  - vtkMeshQuality's hex scaled Jacobian equals our "scaled_jacobian" cell data to 1e-9
    (rockerarm.mesh and the brick, .vtk and .vtu);
  - the gmsh command-line program loads every .msh without an error and counts the same hexes;
  - hexrefine reads the binary .msh files meshio and gmsh write (4.1 and 2.2).
Prints one line per check and a final "N passed, M failed"; exits 1 on any failure.
"""

import contextlib
import io
import os
import subprocess
import sys

FORMATS = [".mesh", ".vtk", "_binary.vtk", ".vtu", "_compressed.vtu", "_ascii.vtu", ".msh",
           "_binary.msh", ".e", ".inp"]
# hexrefine convert's switch for each variant of a format.
SWITCHES = {"_binary.vtk": ["--binary"], "_binary.msh": ["--binary"], "_compressed.vtu": ["--compress"],
            "_ascii.vtu": ["--ascii"]}
# Shared meshes: name -> hex count from shared/meshes/README.md (sphere_sculpt.e: counted by meshio).
SHARED = {
    "rockerarm.mesh": 10600,
    "sphere_conforming.mesh": 125,
    "sphere_projected_inverted.mesh": 111,
    "ellipsoid.mesh": 6816,
    "sphere_sculpt.e": 80,
    "abaqus_hex_2x2x2.inp": 8,
}
QUALITY_MESHES = {"rockerarm", "brick", "sphere_projected_inverted"}

passed = 0
failed = 0


def report(ok, what):
    global passed, failed
    if ok:
        passed += 1
        print("PASS " + what)
    else:
        failed += 1
        print("FAIL " + what)
    sys.stdout.flush()


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return r.returncode, r.stdout


def meshio_hexes(path):
    import meshio

    with contextlib.redirect_stdout(io.StringIO()):  # meshio prints notes; keep one line per check
        mesh = meshio.read(path)
    return sum(len(c.data) for c in mesh.cells if c.type == "hexahedron")


def vtk_grid(path):
    """The unstructured grid in a .vtk/.vtu file, or the blocks of an Exodus file merged."""
    import vtk

    if path.endswith(".vtu"):
        reader = vtk.vtkXMLUnstructuredGridReader()
    elif path.endswith(".vtk"):
        reader = vtk.vtkUnstructuredGridReader()
        reader.ReadAllScalarsOn()
    else:
        reader = vtk.vtkExodusIIReader()
    reader.SetFileName(path)
    if path.endswith(".e"):
        reader.UpdateInformation()
        reader.GenerateGlobalElementIdArrayOn()
    reader.Update()
    out = reader.GetOutput()
    if path.endswith(".e"):
        merge = vtk.vtkAppendFilter()
        it = out.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            merge.AddInputData(it.GetCurrentDataObject())
            it.GoToNextItem()
        merge.Update()
        out = merge.GetOutput()
    return out


def vtk_hexes(grid):
    import vtk

    return sum(1 for i in range(grid.GetNumberOfCells()) if grid.GetCellType(i) == vtk.VTK_HEXAHEDRON)


def vtk_quality_gap(grid):
    """Largest |vtkMeshQuality hex scaled Jacobian - our scaled_jacobian| over the cells."""
    import vtk

    ours = grid.GetCellData().GetArray("scaled_jacobian")
    if ours is None:
        raise RuntimeError("no scaled_jacobian cell data")
    q = vtk.vtkMeshQuality()
    q.SetInputData(grid)
    q.SetHexQualityMeasureToScaledJacobian()
    q.Update()
    theirs = q.GetOutput().GetCellData().GetArray("Quality")
    gap = 0.0
    worst = -1
    for i in range(grid.GetNumberOfCells()):
        d = abs(theirs.GetValue(i) - ours.GetValue(i))
        if d > gap:
            gap, worst = d, i
    return gap, worst


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        return 2
    exe, shared, tmp = sys.argv[1:4]
    meshes_dir = os.path.join(shared, "meshes")
    os.makedirs(tmp, exist_ok=True)

    inputs = {}
    for name, hexes in SHARED.items():
        inputs[os.path.splitext(name)[0]] = (os.path.join(meshes_dir, name), hexes)
    # A jittered brick written by our own writer (`hexrefine generate`); if that command is not
    # available, abaqus_hex_2x2x2.inp converted by our VTK writer stands in for it.
    brick = os.path.join(tmp, "brick_source.vtk")
    code, out = run([exe, "generate", "brick", brick, "--dims", "5,4,3", "--jitter", "0.2", "--seed", "7"])
    if code != 0:
        code, out = run([exe, "convert", os.path.join(meshes_dir, "abaqus_hex_2x2x2.inp"), brick])
        report(code == 0, "brick from abaqus_hex_2x2x2.inp: " + out.strip())
        inputs["brick"] = (brick, 8)
    else:
        report(True, "generate brick 5x4x3: " + out.strip())
        inputs["brick"] = (brick, 60)

    for stem, (source, hexes) in inputs.items():
        for fmt in FORMATS:
            target = os.path.join(tmp, stem + fmt)
            cmd = [exe, "convert", source, target] + SWITCHES.get(fmt, [])
            code, out = run(cmd)
            if code != 0:
                report(False, "hexrefine convert %s -> %s: exit %d: %s" % (source, target, code, out.strip()))
                continue
            try:
                n = meshio_hexes(target)
                report(n == hexes, "meshio reads %s: %d hexes (expected %d)" % (target, n, hexes))
            except Exception as e:  # noqa: BLE001 (any reader failure is a failed check)
                report(False, "meshio reads %s: %s" % (target, e))
            if fmt.endswith(".vtk") or fmt.endswith(".vtu") or fmt == ".e":
                try:
                    grid = vtk_grid(target)
                    n = vtk_hexes(grid)
                    report(n == hexes, "VTK reads %s: %d hexes (expected %d)" % (target, n, hexes))
                    if stem in QUALITY_MESHES and fmt != ".e":
                        gap, worst = vtk_quality_gap(grid)
                        report(gap <= 1e-9, "vtkMeshQuality scaled Jacobian vs ours on %s: max difference %.3g (hex %d)"
                               % (target, gap, worst))
                except Exception as e:  # noqa: BLE001
                    report(False, "VTK reads %s: %s" % (target, e))
            if fmt.endswith(".msh"):
                code, out = run(["gmsh", "-check", target])
                # gmsh warns about inverted hexes (a property of the mesh, e.g. the negative test
                # mesh sphere_projected_inverted); any other warning or error is a failure.
                lines = out.splitlines()
                inverted = [x for x in lines if x.startswith("Warning") and "negative volume" in x]
                errors = [x for x in lines if (x.startswith("Error") or x.startswith("Warning")) and x not in inverted]
                counted = [x.split(":", 1)[-1].strip() for x in lines if x.strip().endswith(" elements")]
                ok = code == 0 and not errors and any(x.split()[0] == str(hexes) for x in counted)
                report(ok, "gmsh -check %s: %s, %d negative-volume warnings%s"
                       % (target, "; ".join(counted) or "no element count", len(inverted),
                          ("; " + "; ".join(errors[:5])) if errors else ""))

    # The other way round: what meshio writes (VTU with inline binary data, zlib-compressed,
    # its default, and uncompressed; ASCII; binary Gmsh) and what gmsh writes our reader takes.
    import meshio
    source = meshio.read(os.path.join(meshes_dir, "rockerarm.mesh"))
    for binary, compression in ((True, "zlib"), (True, None), (False, None)):
        target = os.path.join(tmp, "meshio_%s_%s.vtu" % ("binary" if binary else "ascii", compression))
        try:
            meshio.write(target, source, binary=binary, compression=compression)
        except TypeError:  # older meshio without the compression keyword
            meshio.write(target, source, binary=binary)
        code, out = run([exe, "check", target])
        report(code == 0 and "10600 hexes" in out,
               "hexrefine check reads meshio's %s: %s" % (os.path.basename(target), out.splitlines()[0] if out else ""))

    # Binary Gmsh as meshio (4.1 and 2.2) and the gmsh program (4.1 and 2.2) write it.
    # (hexes only: meshio's 4.1 writer wants entity information for more than one cell type)
    hexes_only = meshio.Mesh(source.points, [(c.type, c.data) for c in source.cells if c.type == "hexahedron"])
    for fmt in ("gmsh", "gmsh22"):
        target = os.path.join(tmp, "meshio_%s_binary.msh" % fmt)
        meshio.write(target, hexes_only, file_format=fmt, binary=True)
        code, out = run([exe, "check", target])
        report(code == 0 and "10600 hexes" in out,
               "hexrefine check reads meshio's %s: %s" % (os.path.basename(target), out.splitlines()[0] if out else ""))
    for version in ("msh41", "msh22"):
        target = os.path.join(tmp, "gmsh_%s_binary.msh" % version)
        code, out = run(["gmsh", "-0", "-bin", "-format", version, os.path.join(tmp, "rockerarm.msh"), "-o", target])
        if code != 0:
            report(False, "gmsh -0 -bin -format %s: exit %d: %s" % (version, code, out.strip()[-300:]))
            continue
        code, out = run([exe, "check", target])
        report(code == 0 and "10600 hexes" in out,
               "hexrefine check reads gmsh's %s: %s" % (os.path.basename(target), out.splitlines()[0] if out else ""))

    print("%d passed, %d failed" % (passed, failed))
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
