#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""sph-run's interchange outputs and its user-facing switches (issue 22, items 4 and 5).

usage: test_interchange.py SPH_RUN SCENES_DIR

- .vtp frames read back through VTK's own reader (python3-vtk9) hold every attribute, equal to
  the same frame's PLY (positions, velocities, densities, ids: the same floats, so exactly) and
  CSV (pressures, printed with 9 significant digits, so to float precision), with one vertex
  cell per particle and the frame's time as TimeValue;
- fluid.pvd lists every frame's .vtp with the frame's time (frame / fps);
- in builds with OpenVDB, the surface OBJ has one unit normal a vertex, pointing out of the fluid;
- --preview draws the caption (bright text in the top-left corner on a dark background) and,
  for particles, the speed legend in the bottom-left;
- --preview-style surface without --surface is a usage error, and a misspelt option names
  the nearest real one.
Tests needing a module the machine lacks are skipped, and say so; the run fails on any failure.
"""
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import numpy as np

SPH_RUN, SCENES = sys.argv[1], sys.argv[2]
SCENE = os.path.join(SCENES, "tiny.json")
FPS = 50.0  # tiny.json's time.fps
failures = []
passed = skipped = 0


def check(name, condition, detail=""):
    global passed
    if condition:
        passed += 1
        print(f"ok   {name}")
    else:
        failures.append(name)
        print(f"FAIL {name} {detail}")


def skip(name, why):
    global skipped
    skipped += 1
    print(f"skip {name}: {why}")


def run(*args, expect=0):
    p = subprocess.run([SPH_RUN, SCENE, "--backend", "cpu", "--quiet", *args], capture_output=True, text=True)
    if p.returncode != expect:
        raise SystemExit(f"sph-run {' '.join(args)}: exit {p.returncode}, expected {expect}\n{p.stderr}")
    return p


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    n = int(header.split("element vertex ")[1].split()[0])
    rec = np.dtype([("p", "<f4", 3), ("v", "<f4", 3), ("density", "<f4"), ("id", "<u4")])
    return np.frombuffer(data[end:], dtype=rec, count=n)


version = subprocess.run([SPH_RUN, "--version"], capture_output=True, text=True).stdout
have_surface = "surfaces" in version
have_png = "preview" in version

with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "out")
    extra = ["--surface"] if have_surface else []
    run("--frames", "3", "--format", "vtp,ply,csv", "--out", out, *extra)

    # ---- the series ----
    series = ET.parse(os.path.join(out, "fluid.pvd")).getroot()
    sets = series.findall("./Collection/DataSet")
    check("pvd lists frames 0..3", [d.get("file") for d in sets] == [f"fluid_{i:04d}.vtp" for i in range(4)],
          [d.get("file") for d in sets])
    check("pvd timesteps are frame / fps",
          np.allclose([float(d.get("timestep")) for d in sets], np.arange(4) / FPS, rtol=0, atol=1e-9))

    # ---- the frames, through VTK ----
    try:
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
    except ImportError as e:
        vtkXMLPolyDataReader = None
        skip("vtp read back with VTK", f"no VTK Python module ({e}); install python3-vtk9")
    if vtkXMLPolyDataReader is not None:
        for i in range(4):
            reader = vtkXMLPolyDataReader()
            reader.SetFileName(os.path.join(out, f"fluid_{i:04d}.vtp"))
            reader.Update()
            poly = reader.GetOutput()
            ply = read_ply(os.path.join(out, f"fluid_{i:04d}.ply"))
            csv = np.loadtxt(os.path.join(out, f"fluid_{i:04d}.csv"), delimiter=",", skiprows=1, ndmin=2)
            n = poly.GetNumberOfPoints()
            pd = poly.GetPointData()
            arrays = {pd.GetArrayName(k): vtk_to_numpy(pd.GetArray(k)) for k in range(pd.GetNumberOfArrays())}
            tag = f"frame {i}"
            check(f"{tag}: {n} points, as many as the PLY ({len(ply)})", n == len(ply) and n > 0)
            check(f"{tag}: point data is velocity, density, pressure, id",
                  sorted(arrays) == ["density", "id", "pressure", "velocity"], sorted(arrays))
            check(f"{tag}: positions equal the PLY's", np.array_equal(vtk_to_numpy(poly.GetPoints().GetData()), ply["p"]))
            check(f"{tag}: velocities equal the PLY's", np.array_equal(arrays["velocity"], ply["v"]))
            check(f"{tag}: densities equal the PLY's", np.array_equal(arrays["density"], ply["density"]))
            check(f"{tag}: ids equal the PLY's", np.array_equal(arrays["id"], ply["id"]))
            # CSV: id,x,y,z,vx,vy,vz,density,pressure with 9 significant digits (exact for float32).
            check(f"{tag}: pressures equal the CSV's",
                  np.array_equal(arrays["pressure"], csv[:, 8].astype(np.float32)) and np.array_equal(
                      arrays["id"], csv[:, 0].astype(np.uint32)))
            check(f"{tag}: one vertex cell a particle", poly.GetNumberOfVerts() == n)
            t = vtk_to_numpy(poly.GetFieldData().GetArray("TimeValue"))
            check(f"{tag}: TimeValue {t[0]} = {i} / fps", abs(t[0] - i / FPS) < 1e-9)

    # ---- surface normals ----
    if have_surface:
        v, vn, faces, corners = [], [], [], []
        with open(os.path.join(out, "surface_0003.obj")) as f:
            for line in f:
                w = line.split()
                if w and w[0] == "v":
                    v.append([float(x) for x in w[1:4]])
                elif w and w[0] == "vn":
                    vn.append([float(x) for x in w[1:4]])
                elif w and w[0] == "f":
                    faces.append([int(x.split("//")[0]) for x in w[1:4]])
                    corners += [x.split("//") for x in w[1:4]]
        v, vn, faces = np.array(v), np.array(vn), np.array(faces) - 1
        check("obj: one normal a vertex", len(v) == len(vn) > 0, (len(v), len(vn)))
        check("obj: unit normals", np.allclose(np.linalg.norm(vn, axis=1), 1.0, atol=1e-4))
        # The faces wind counter-clockwise seen from outside: the signed volume they enclose
        # (divergence theorem, sum of a . (b x c) / 6) is positive. Each vertex normal then
        # points out where its faces do: it agrees in sign with the normal of (nearly) every
        # face that uses it (a few corners on sharp folds of the mesh may not).
        a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
        volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
        check(f"obj: faces wind outward (enclosed volume {volume:.3g} m^3 > 0)", volume > 0)
        face_n = np.cross(b - a, c - a)
        agree = np.concatenate([np.einsum("ij,ij->i", face_n, vn[faces[:, k]]) > 0 for k in range(3)])
        check(f"obj: vertex normals agree with their faces ({agree.mean():.1%} of corners)", agree.mean() > 0.97)
        check("obj: each corner names its vertex's normal (f a//a)", all(len(c) == 2 and c[0] == c[1] for c in corners))
    else:
        skip("obj normals", "this build has no OpenVDB (no surfaces)")

    # ---- the preview caption ----
    if have_png:
        try:
            import matplotlib.image as mpimg
        except ImportError:
            mpimg = None
            skip("preview caption", "no matplotlib to read the PNG")
        if mpimg is not None:
            prev = os.path.join(tmp, "prev")
            run("--frames", "1", "--format", "none", "--preview", "--out", prev)
            img = mpimg.imread(os.path.join(prev, "preview_0001.png"))[:, :, :3]
            h, w = img.shape[:2]
            # The caption's font pixels are near white (0.92 linear); the background is near black
            # and the fluid is blue (red channel at most 0.8 at full speed).
            corner = img[: h // 20, : w // 2]
            check("caption drawn in the top-left", (corner.min(axis=2) > 0.85).sum() > 50)
            legend = img[-h // 8:, : w // 4]
            check("speed legend drawn in the bottom-left", (legend[:, :, 2] > 0.5).sum() > 100
                  and (legend.min(axis=2) > 0.85).sum() > 20)
    else:
        skip("preview caption", "this build has no libpng")

    # ---- the command line ----
    p = run("--frames", "1", "--preview-style", "surface", "--format", "none", "--out", out + "2", expect=2)
    check("--preview-style surface without --surface is a usage error", "--surface" in p.stderr, p.stderr)
    p = run("--frame", "1", expect=2)
    check("--frame names --frames", "did you mean --frames?" in p.stderr, p.stderr)
    p = run("--preview-styl", "particles", expect=2)
    check("--preview-styl names --preview-style", "did you mean --preview-style?" in p.stderr, p.stderr)
    p = run("--xyzzyplugh", expect=2)
    check("a foreign word gets no guess", "did you mean" not in p.stderr and "--help" in p.stderr, p.stderr)
    check("a usage error does not reprint the usage", "exit codes:" not in p.stderr, p.stderr)

# ---- the user attribute: a source's value in every format, 0 for the other particles ----
with tempfile.TemporaryDirectory() as tmp:
    with open(SCENE) as f:
        scene = json.load(f)
    scene["sources"][0]["user_attribute"] = 9
    path = os.path.join(tmp, "tagged.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    out = os.path.join(tmp, "out")
    p = subprocess.run([SPH_RUN, path, "--backend", "cpu", "--quiet", "--frames", "3", "--format", "vtp,ply,csv",
                        "--out", out], capture_output=True, text=True)
    check("a scene whose source has a user_attribute runs", p.returncode == 0, p.stderr)
    if p.returncode == 0:
        with open(os.path.join(out, "fluid_0003.ply"), "rb") as f:
            data = f.read()
        end = data.index(b"end_header\n") + len(b"end_header\n")
        check("ply: a uint user property after the id", b"property uint id\nproperty uint user\nend_header" in data)
        n = int(data[:end].decode().split("element vertex ")[1].split()[0])
        rec = np.dtype([("p", "<f4", 3), ("v", "<f4", 3), ("density", "<f4"), ("id", "<u4"), ("user", "<u4")])
        ply = np.frombuffer(data[end:], dtype=rec, count=n)
        # tiny.json: the source emits from 0.02 s on, after the first fluids took their ids.
        check("ply: the source's particles carry 9, the others 0",
              set(np.unique(ply["user"]).tolist()) == {0, 9}, np.unique(ply["user"]))
        csv = np.loadtxt(os.path.join(out, "fluid_0003.csv"), delimiter=",", skiprows=1, ndmin=2)
        check("csv: the user column equals the PLY's", np.array_equal(csv[:, 9].astype(np.uint32), ply["user"]))
        try:
            from vtkmodules.util.numpy_support import vtk_to_numpy
            from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
            reader = vtkXMLPolyDataReader()
            reader.SetFileName(os.path.join(out, "fluid_0003.vtp"))
            reader.Update()
            user = vtk_to_numpy(reader.GetOutput().GetPointData().GetArray("user"))
            check("vtp: the user array equals the PLY's", np.array_equal(user, ply["user"]))
        except ImportError as e:
            skip("vtp user array", f"no VTK Python module ({e})")

print(f"{passed} passed, {len(failures)} failed, {skipped} skipped")
sys.exit(1 if failures else 0)
