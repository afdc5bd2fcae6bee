"""The Python module against the command and the library's own checks.

Run by ctest (python_module) with PYTHONPATH at build/python, or by hand:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python
"""
import base64
import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import skinmesh

DATA = os.environ.get("SKINMESH_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "data"))
BINARY = os.environ.get("SKINMESH_BINARY", "")


def data(name):
    return os.path.join(DATA, name)


def test_version():
    assert skinmesh.__version__.count(".") == 2


def test_mesh_arrays_equal_the_command():
    m = skinmesh.mesh(data("pept.pdb"))
    assert m.vertices.dtype == np.float64 and m.vertices.shape[1] == 3
    assert m.triangles.dtype == np.int64 and m.triangles.shape[1] == 3
    assert m.triangles.max() < len(m.vertices)
    assert set(m.attributes) == {"atom", "patch", "normals"}
    assert m.attributes["atom"].shape == (len(m.vertices),)
    assert all(m.report["guarantees"].values())
    assert m.report["quality"]["min_angle_deg"] >= 30.0
    # The command on the same input: the same mesh, bit for bit.
    import meshio

    assert BINARY, "SKINMESH_BINARY names the command (ctest sets it)"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "pept.ply")
        report = os.path.join(d, "pept.json")
        subprocess.run([BINARY, "--quiet", "mesh", data("pept.pdb"), "-o", out, "--report", report], check=True)
        with open(report) as f:
            command = json.load(f)
        ply = meshio.read(out)
    # the report --report writes, less what only the command knows
    assert set(command) - {"command_line", "output", "format", "atom_table", "colour"} == set(m.report)
    assert command["quality"] == m.report["quality"]
    assert command["quality"]["vertices"] == len(m.vertices)
    assert command["quality"]["euler_characteristic"] == m.report["quality"]["euler_characteristic"]
    assert np.array_equal(ply.points, m.vertices)
    assert np.array_equal(ply.cells_dict["triangle"], m.triangles)


def test_vertices_are_handed_over_without_a_copy():
    m = skinmesh.mesh(data("pept.pdb"))
    assert not m.vertices.flags["OWNDATA"]  # the library's memory, kept alive by the array
    assert m.vertices.flags["C_CONTIGUOUS"]


def test_mesh_from_centres_and_radii_equals_the_file():
    from_file = skinmesh.mesh(data("pept.pdb"))
    lines = [l for l in open(data("pept.pdb")) if l.startswith(("ATOM", "HETATM"))]
    assert len(lines) > 0
    one = skinmesh.mesh((np.zeros((1, 3)), np.array([1.5])))
    # one atom of radius 1.5 A: the skin is the sphere of radius 1.5 A (weights r^2/s)
    r = np.linalg.norm(one.vertices, axis=1)
    assert np.allclose(r, 1.5, atol=1e-9)
    assert one.report["quality"]["components"] == 1
    assert from_file.report["quality"]["components"] >= 1


def test_grade_of_any_mesh():
    m = skinmesh.mesh(data("pept.pdb"))
    g = skinmesh.grade(m.vertices, m.triangles)
    assert g["triangles"] == len(m.triangles)
    assert g["closed"] and g["manifold"] and g["consistently_oriented"]
    with pytest.raises(ValueError):
        skinmesh.grade(m.vertices, m.triangles + len(m.vertices))


def test_bad_input_raises_with_file_and_line():
    with tempfile.TemporaryDirectory() as d:
        bad = os.path.join(d, "bad.xyzr")
        with open(bad, "w") as f:
            f.write("1 2 3 1.5\n1 2 x 1.5\n")
        with pytest.raises(skinmesh.InputError) as e:
            skinmesh.mesh(bad)
        assert e.value.file == bad
        assert e.value.line == 2
    with pytest.raises(TypeError):
        skinmesh.mesh(data("pept.pdb"), no_such_option=1)


def test_moving_balls_keep_ids_and_every_frame_holds():
    lines = [l for l in open(data("pept.pdb")) if l.startswith(("ATOM", "HETATM"))]
    centres = np.array([[float(l[30:38]), float(l[38:46]), float(l[46:54])] for l in lines])
    radii = np.full(len(centres), 1.7)
    stages = []
    moving = skinmesh.MovingBalls(radii, progress=lambda stage, vertices, expected: stages.append(stage))
    first = moving.advance_to(centres, 0.0)
    assert "refining" in stages or "seeding" in stages  # the first frame's mesh reported its progress
    for k in range(1, 4):
        f = moving.advance_to(centres + np.array([0.3 * k, 0, 0]), float(k))
        assert f.report["guarantees"]["min_angle_at_least_bound"] and f.report["guarantees"]["vertices_on_skin"]
        assert f.report["guarantees"]["topology"]
        assert f.report["topology_certified"]
        assert np.array_equal(f.ids, first.ids)  # a rigid translation keeps every vertex
        assert np.allclose(f.vertices, first.vertices + np.array([0.3 * k, 0, 0]), atol=1e-9)


def test_moving_balls_told_the_next_centres_make_the_same_frames():
    lines = [l for l in open(data("pept.pdb")) if l.startswith(("ATOM", "HETATM"))]
    centres = np.array([[float(l[30:38]), float(l[38:46]), float(l[46:54])] for l in lines])
    radii = np.full(len(centres), 1.7)
    middle = centres.mean(axis=0)
    path = [middle + (centres - middle) * (1 + 0.02 * k) for k in range(5)]  # swelling: the mesh is mended
    plain = skinmesh.MovingBalls(radii)
    frames = [plain.advance_to(c, float(k)) for k, c in enumerate(path)]
    told = list(skinmesh.MovingBalls(radii).frames(path))  # each call told the next centres
    assert len(told) == len(frames)
    for f, g in zip(frames, told):
        assert np.array_equal(f.vertices, g.vertices)
        assert np.array_equal(f.triangles, g.triangles)
        assert np.array_equal(f.ids, g.ids)
    assert sum(f.report.get("steps_built_ahead", 0) for f in frames) == 0
    assert sum(g.report["steps_built_ahead"] for g in told[1:]) >= len(told) - 2  # all but the first call's
    with pytest.raises(ValueError):
        skinmesh.MovingBalls(radii).advance_to(centres, 0.0, next=centres[:3])


def test_morph_frames_are_valid_and_ids_continue():
    morph = skinmesh.Morph(data("2k39_3models.pdb"), data("2k39_3models.pdb"), model=1)
    assert morph.matched  # one molecule: its atoms travel
    ids = set(morph.frame.ids.tolist())
    f = list(morph.frames([0.25, 0.5]))[-1]
    assert f.report["guarantees"]["min_angle_at_least_bound"] and f.report["guarantees"]["vertices_on_skin"]
    assert f.report["guarantees"]["topology"]
    assert len(ids & set(f.ids.tolist())) > 0.5 * len(f.ids)
    blend = skinmesh.Morph(data("pept.pdb"), data("3al1.pdb"))
    assert not blend.matched
    g = blend.advance_to(0.5)
    assert g.report["guarantees"]["vertices_on_skin"] and g.report["guarantees"]["topology"]
    # As the files hold them: no negative atom value, the missing side a flag
    # (at t = 1 the blend's mesh is the target's own: no source atoms).
    for frame, side in ((g, None), (blend.advance_to(1.0), "source")):
        a = frame.attributes
        for name in ("atom", "atomid", "source_atom", "target_atom", "has_source_atom", "has_target_atom"):
            assert a[name].min() >= 0, name
        assert np.array_equal(a["atomid"], np.where(a["has_source_atom"] == 1, a["source_atom"], a["target_atom"]))
        if side == "source":
            assert not a["has_source_atom"].any() and a["has_target_atom"].all()


def test_meshio_reads_every_frame_format_with_unsigned_atoms():
    import xml.etree.ElementTree as ET

    import meshio

    assert BINARY, "SKINMESH_BINARY names the command (ctest sets it)"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "m")
        pdb = data("2k39_3models.pdb")
        subprocess.run([BINARY, "--quiet", "morph", pdb, pdb, "--source-model", "1", "--target-model", "3", "--pairs",
                        "all", "--frames", "2", "--format", "ply,vtp,off,obj,stl", "-o", out], check=True)
        for k in (0, 1):
            missing = "has_target_atom" if k == 0 else "has_source_atom"  # an end frame is one side's own mesh
            for ext in ("ply", "off", "obj", "stl"):  # meshio 5 has no VTP reader: the VTP is read as XML below
                m = meshio.read(os.path.join(out, f"frame_000{k}.{ext}"))
                assert len(m.cells_dict["triangle"]) > 0
            ply = meshio.read(os.path.join(out, f"frame_000{k}.ply"))
            for name in ("atomid", "source_atom", "target_atom"):
                assert ply.point_data[name].dtype.kind == "u", name  # Mol* reads them unsigned
            assert not ply.point_data[missing].any()
            arrays = {a.get("Name"): a for a in ET.parse(os.path.join(out, f"frame_000{k}.vtp")).iter("DataArray")}
            for name in ("atomid", "source_atom", "target_atom"):
                assert arrays[name].get("type") == "UInt32", name
            values = vtp_binary_array(arrays["atomid"])
            assert len(values) == len(ply.points) and values.min() >= 0
            assert np.array_equal(values, ply.point_data["atomid"])
            assert not vtp_binary_array(arrays[missing]).any()
            assert np.array_equal(vtp_binary_array(arrays[None]).reshape(-1, 3), ply.points)
            assert np.array_equal(vtp_binary_array(arrays["connectivity"]).reshape(-1, 3), ply.cells_dict["triangle"])


def vtp_binary_array(element):
    """A VTK XML data array of format binary: base64 of a UInt64 byte count, then the values (little endian)."""
    types = {"Float64": "<f8", "Float32": "<f4", "Int64": "<i8", "Int32": "<i4", "UInt32": "<u4", "UInt8": "u1"}
    assert element.get("format") == "binary"
    raw = base64.b64decode(element.text.strip())
    count = int(np.frombuffer(raw[:8], dtype="<u8")[0])
    assert count == len(raw) - 8
    return np.frombuffer(raw[8:], dtype=types[element.get("type")])


def test_meshio_writes_what_the_module_returns():
    import meshio
    m = skinmesh.mesh(data("pept.pdb"))
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "pept.vtu")
        meshio.write(path, meshio.Mesh(m.vertices, [("triangle", m.triangles)]))
        back = meshio.read(path)
        assert len(back.points) == len(m.vertices)


def test_an_mdanalysis_trajectory_becomes_a_continuous_morph():
    import MDAnalysis as mda
    from MDAnalysis.analysis import align

    with tempfile.TemporaryDirectory() as d:
        # The ensemble's three models written as a DCD trajectory by MDAnalysis, read back through it.
        models = mda.Universe(data("2k39_3models.pdb"))
        heavy = models.select_atoms("not element H")
        dcd = os.path.join(d, "2k39.dcd")
        with mda.Writer(dcd, heavy.n_atoms) as w:
            for _ in models.trajectory:
                w.write(heavy)
        pdb = os.path.join(d, "first.pdb")
        models.trajectory[0]
        heavy.write(pdb)
        u = mda.Universe(pdb, dcd)
        assert len(u.trajectory) == 3
        align.AlignTraj(u, u, select="all", in_memory=True).run()
        radii = np.array([{"C": 1.7, "N": 1.55, "O": 1.52, "S": 1.8}.get(e, 1.8) for e in u.atoms.elements])
        moving = skinmesh.MovingBalls(radii)
        before = None
        frames = []
        for ts in u.trajectory:
            f = moving.advance_to(u.atoms.positions.astype(np.float64), float(ts.frame))
            frames.append(f)
            assert f.report["guarantees"]["min_angle_at_least_bound"] and f.report["guarantees"]["vertices_on_skin"]
            assert f.report["guarantees"]["topology"]
            if before is not None:
                assert len(before & set(f.ids.tolist())) > 0  # the same mesh carried on
            before = set(f.ids.tolist())
        # ... and a morph directory as `skinmesh morph` writes one.
        out = os.path.join(d, "morph")
        skinmesh.write_frames(out, frames)
        assert sorted(os.listdir(out)) == ["frame_0000.ply", "frame_0000.vtp", "frame_0001.ply", "frame_0001.vtp",
                                           "frame_0002.ply", "frame_0002.vtp", "frames.jsonl", "frames.pvd"]
        import meshio

        ply = meshio.read(os.path.join(out, "frame_0002.ply"))
        assert np.array_equal(ply.points, frames[2].vertices)
        assert np.array_equal(np.asarray(ply.point_data["id"]), frames[2].ids)
        lines = [json.loads(l) for l in open(os.path.join(out, "frames.jsonl"))]
        assert [l["t"] for l in lines] == [0.0, 1.0, 2.0]
        with pytest.raises(ValueError):
            skinmesh.write_frames(os.path.join(d, "bad"), frames, formats=["ply", "xyz"])
        assert not os.path.exists(os.path.join(d, "bad"))


def test_complex_counts_and_topology_equal_the_mesh():
    c = skinmesh.complex(data("pept.pdb"))
    m = skinmesh.mesh(data("pept.pdb"))
    assert c["balls"] == m.report["atoms"]
    assert len(c["cells"]) == 4 and c["cells"][0] == c["balls"] - c["hidden_balls"]
    assert c["components"] == m.report["quality"]["components"]
    assert c["euler"] == m.report["quality"]["euler_characteristic"]


def test_interpolate_equals_the_command():
    centres, weights = skinmesh.interpolate(data("pept.pdb"), data("3al1.pdb"), 0.5)
    assert centres.shape == (len(weights), 3)
    assert BINARY, "SKINMESH_BINARY names the command (ctest sets it)"
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "mid.wpts")
        subprocess.run([BINARY, "--quiet", "interpolate", data("pept.pdb"), data("3al1.pdb"), "--t", "0.5", "-o", out],
                       check=True)
        rows = np.array([[float(x) for x in l.split()] for l in open(out) if l.strip() and not l.startswith("#")])
    assert len(rows) == len(weights)
    assert np.allclose(rows[:, :3], centres, atol=1e-12) and np.allclose(rows[:, 3], weights, atol=1e-12)


def test_volume_mesh_of_a_peptide():
    v = skinmesh.volume(data("pept.pdb"))
    assert v.points.shape[1] == 3 and v.tetrahedra.shape[1] == 4
    assert v.tetrahedra.max() < len(v.points)
    p = v.points[v.tetrahedra]
    signed = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    assert (signed > 0).all()  # positively oriented
    assert set(np.unique(v.tetrahedron_region)) <= {1, 3}
