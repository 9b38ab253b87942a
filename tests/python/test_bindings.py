"""The fissure module's surface: shapes, dtypes and units of its arrays, errors crossing the
boundary with their text and parts, and the documentation help() shows."""
import math
import pydoc
import subprocess

import numpy as np
import pytest

import fissure



@pytest.fixture(scope="module")
def scene():
    return fissure.Scene.load("spatula-sphere")


@pytest.fixture(scope="module")
def settled(scene):
    sim = fissure.HostSimulation(scene)
    sim.settle(0.2)
    return sim


def test_scene_loads_by_name_with_its_figures(scene):
    assert scene.name == "spatula-sphere"
    assert scene.source_path.endswith("scenes/spatula-sphere.toml")
    assert scene.collision_method == "paired"
    assert scene.tool_kind == "box" and scene.soft_shape == "sphere"
    assert scene.time_step_s == pytest.approx(0.001)
    np.testing.assert_array_equal(scene.tool_box_size_m, [0.03, 0.002, 0.06])
    hc = scene.hunt_crossley
    assert (hc["n"], hc["k"], hc["per_unit_area"]) == (1.5, 1.0e7, True)
    pose, _ = scene.sample_trajectory(0.0)
    np.testing.assert_array_equal(pose.position, [0.0, 0.12, 0.0])
    assert scene.trajectory_duration_s > 0.5 and scene.hand_duration_s > 1.0


def test_scene_error_carries_file_line_and_field(source_dir):
    # The unit is part of every key's name: radius in millimetres where metres are expected.
    with open(f"{source_dir}/scenes/spatula-sphere.toml", encoding="utf-8") as f:
        lines = f.read().splitlines()
    line = next(i for i, text in enumerate(lines, start=1) if text.startswith("radius_m ="))
    lines[line - 1] = "radius_mm = 50.0"
    with pytest.raises(fissure.SceneError) as caught:
        fissure.Scene.from_toml("\n".join(lines), label="bad-unit.toml")
    e = caught.value
    assert isinstance(e, ValueError)
    assert (e.file, e.line, e.field) == ("bad-unit.toml", line, "soft_body.radius_mm")
    assert str(e).startswith(f"bad-unit.toml:{line}: field 'soft_body.radius_mm'")


def test_scene_error_for_toml_syntax_and_missing_file(tmp_path):
    with pytest.raises(fissure.SceneError) as caught:
        fissure.Scene.from_toml("[scene\n", label="syntax.toml")
    assert caught.value.file == "syntax.toml" and caught.value.line == 1 and "TOML syntax error" in str(caught.value)
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(fissure.SceneError) as caught:
        fissure.Scene.load(str(missing))
    assert caught.value.line == 0 and str(missing) in str(caught.value)


def test_implausible_scene_is_refused_unless_asked_not_to(source_dir):
    with open(f"{source_dir}/scenes/spatula-sphere.toml", encoding="utf-8") as f:
        text = f.read().replace("radius_m = 0.05", "radius_m = 50.0")
    with pytest.raises(fissure.SceneError) as caught:
        fissure.Scene.from_toml(text, label="huge.toml")
    assert caught.value.field == "soft_body.radius_m" and "implausible" in str(caught.value)
    assert fissure.Scene.from_toml(text, label="huge.toml", check_plausible=False).name


def test_soft_body_arrays_have_documented_shapes(settled):
    n, f = settled.soft_node_count, settled.soft_face_count
    nodes = settled.node_positions()
    assert nodes.shape == (n, 3) and nodes.dtype == np.float64
    faces = settled.faces()
    assert faces.shape == (f, 3) and faces.dtype == np.int32
    assert f == 128 and faces.min() == 0 and faces.max() == n - 1
    rest = settled.rest_positions()
    assert rest.shape == (n, 3)
    # settle() makes the settled shape the rest state, and nothing has moved since.
    np.testing.assert_array_equal(rest, nodes)
    bounds = settled.soft_bounds()
    assert bounds.shape == (2, 3)
    np.testing.assert_array_equal(bounds[0], nodes.min(axis=0))
    np.testing.assert_array_equal(bounds[1], nodes.max(axis=0))
    # Metres: a 5 cm ball resting on the ground at y = 0.
    assert 0.09 < bounds[1, 1] < 0.11 and abs(bounds[0, 1]) < 0.01


def test_node_view_is_live_and_read_only():
    sim = fissure.HostSimulation(fissure.Scene.load("spatula-sphere"))
    view = sim.node_positions_view()
    copy = sim.node_positions()
    assert not view.flags.writeable
    assert not np.shares_memory(view, copy)
    np.testing.assert_array_equal(view, copy)
    sim.step([0.0, 0.12, 0.0])
    np.testing.assert_array_equal(view, sim.node_positions())
    assert not np.array_equal(view, copy)  # the ball fell under gravity during the step
    with pytest.raises(ValueError):
        view[0, 0] = 1.0


def test_step_result_in_contact(scene):
    sim = fissure.HostSimulation(scene)
    sim.settle(0.2)
    top = sim.soft_bounds()[1, 1]
    dt = scene.time_step_s
    y = top + 0.002
    r = None
    while y > top - 0.004:
        y -= 0.05 * dt
        r = sim.step([0.0, y, 0.0])
    assert r.time_s == pytest.approx(sim.time_s) and sim.time_s > 0.1
    assert r.force.shape == (3,) and r.force[1] > 0.5  # the ball pushes the spatula up [N]
    assert r.part_count == 1 and r.part_forces.shape == (1, 3)
    np.testing.assert_allclose(r.part_forces.sum(axis=0), r.force, rtol=1e-12)
    c = r.contacts
    count = r.contact_count
    assert count > 0
    for key in ("soft_face", "tool_node", "tool_plane", "jaw"):
        assert c[key].shape == (count,) and c[key].dtype == np.int32
    for key in ("point_world_m", "normal_world"):
        assert c[key].shape == (count, 3) and c[key].dtype == np.float64
    for key in ("penetration_m", "penetration_rate_m_s", "weight", "force_n"):
        assert c[key].shape == (count,)
    assert c["soft_face"].max() < sim.soft_face_count
    np.testing.assert_allclose(np.linalg.norm(c["normal_world"], axis=1), 1.0, rtol=1e-9)
    assert 0.0 < c["penetration_m"].max() < 0.01  # metres: a few millimetres
    assert r.crossed_nodes == 0 and 0.0 <= r.penetration_m < fissure.INSIDE_TOLERANCE_M
    assert set(r.times) == {"bullet_s", "collision_s", "metrics_s", "total_s"}
    assert r.cut_triangles == -1
    assert sim.step([0.0, y, 0.0], count_cut_triangles=True).cut_triangles >= 0
    assert r.part_reports[0]["contacted_triangles"] == count
    np.testing.assert_allclose(sim.tool_pose.position, [0.0, y, 0.0])
    nodes = sim.tool_nodes(0)
    m = nodes["positions_tool_m"].shape[0]
    assert nodes["normals_tool"].shape == (m, 3) and nodes["pair_of"].shape == (m,) and nodes["is_thin"]
    np.testing.assert_allclose(nodes["positions_world_m"], nodes["positions_tool_m"] + [0.0, y, 0.0], atol=1e-15)
    assert nodes["thickness_m"] == pytest.approx(0.002)


def test_tool_pose_forms(scene):
    sim = fissure.HostSimulation(scene)
    sim.step(fissure.ToolPose([0.0, 0.13, 0.0], [1.0, 0.0, 0.0, 0.0]))
    sim.step([0.0, 0.13, 0.001, 0.0, 0.0, 1.0, 0.0])  # 180° about y
    np.testing.assert_allclose(sim.tool_pose.orientation_wxyz, [0.0, 0.0, 1.0, 0.0])
    sim.step([0.0, 0.13, 0.002])  # a position keeps the orientation
    np.testing.assert_allclose(sim.tool_pose.orientation_wxyz, [0.0, 0.0, 1.0, 0.0])
    np.testing.assert_allclose(sim.tool_pose.rotation_matrix() @ [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], atol=1e-15)
    with pytest.raises(ValueError, match="got 4 numbers"):
        sim.step([0.0, 0.1, 0.0, 1.0])


def test_clamp_has_two_jaws_and_a_gap():
    scene = fissure.Scene.load("clamp-sphere")
    sim = fissure.HostSimulation(scene)
    assert sim.part_count == 2
    pose, gap = scene.sample_trajectory(0.0)
    r = sim.step(pose, jaw_gap=-1.0)  # clamped to the scene's minimum gap
    assert r.part_forces.shape == (2, 3)
    assert 0.0 <= r.jaw_gap_m < gap
    assert sim.step(pose).jaw_gap_m == r.jaw_gap_m  # None keeps the gap
    a, b = sim.tool_nodes(0), sim.tool_nodes(1)
    jaw_a, jaw_b = a["part_pose"].position, b["part_pose"].position
    assert np.linalg.norm(jaw_a - jaw_b) > r.jaw_gap_m  # the jaws sit either side of the gap
    with pytest.raises(IndexError):
        sim.tool_nodes(2)


def test_bullet_method_has_no_tool_nodes(scene):
    sim = fissure.HostSimulation(scene, method="bullet")
    assert sim.method == "bullet" and sim.tool_nodes(0) is None
    with pytest.raises(ValueError, match="expected paired, ray or bullet"):
        fissure.HostSimulation(scene, method="magic")


def test_kinematics_shapes_units_and_round_trip():
    centre = np.asarray(fissure.WORKSPACE_CENTRE_DEVICE_M)
    theta = fissure.ik(centre)
    assert theta.shape == (3,) and np.all(np.abs(theta) < math.pi / 2)  # radians
    np.testing.assert_allclose(fissure.fk(theta), centre, atol=1e-9)
    points = centre + np.array([[0.0, 0.0, 0.0], [0.02, -0.01, 0.01], [-0.03, 0.02, -0.02], [5.0, 0.0, 0.0]])
    thetas = fissure.ik(points)
    assert thetas.shape == (4, 3) and np.isnan(thetas[3]).all() and np.isfinite(thetas[:3]).all()
    np.testing.assert_allclose(fissure.fk(thetas[:3]), points[:3], atol=1e-9)
    jac = fissure.jacobian(points)
    assert jac.shape == (4, 3, 3) and np.isnan(jac[3]).all()
    assert fissure.jacobian(centre).shape == (3, 3)
    # J = ∂p/∂θ: a small motor step moves the end effector by J·dθ [m].
    dtheta = np.array([1e-6, -2e-6, 1.5e-6])
    np.testing.assert_allclose(fissure.fk(thetas[1] + dtheta) - points[1], jac[1] @ dtheta, atol=1e-10)
    assert fissure.in_workspace(centre) is True
    np.testing.assert_array_equal(fissure.in_workspace(points), [True, True, True, False])
    with pytest.raises(ValueError, match=r"expected shape \(3,\) or \(N, 3\)"):
        fissure.ik(np.zeros(4))


def test_session_errors_cross_with_their_text(scene):
    with pytest.raises(ValueError, match="needs the paired or ray collision method"):
        fissure.run_session(scene, method="bullet", duration_s=0.01, settle_s=0.0)
    with pytest.raises(fissure.SessionError) as caught:
        fissure.run_session(scene, host_rate=300.0, duration_s=0.01, settle_s=0.0)
    assert "300" in str(caught.value)
    with pytest.raises(ValueError, match="expected sim or usb"):
        fissure.run_session(scene, device="glove", duration_s=0.01, settle_s=0.0)


def test_eval_error_crosses_with_its_text():
    with pytest.raises(fissure.EvalError) as caught:
        fissure.stress(cases=["no_such_case"])
    assert "no_such_case" in str(caught.value) and caught.value.bad_argument
    names = fissure.stress_case_names()
    assert "hand_random" in names and all(isinstance(n, str) for n in names)


def test_help_documents_the_surface():
    text = pydoc.render_doc(fissure.HostSimulation, renderer=pydoc.plaintext)
    for phrase in ("settle(", "Hunt-Crossley rest state", "step(", "jaw_gap", "node_positions_view(", "(N, 3) float64",
                   "faces(", "tool_nodes(", "reseat_tool("):
        assert phrase in text, phrase
    step_text = pydoc.render_doc(fissure.StepResult, renderer=pydoc.plaintext)
    for phrase in ("part_forces", "(P, 3)", "contacts", "crossed_nodes", "penetration_m", "times"):
        assert phrase in step_text, phrase
    assert "FILE, LINE and FIELD" in fissure.Scene.load.__doc__


def test_contact_response_and_tool_friction_reach_python():
    lift = fissure.Scene.load("clamp-vessel-lift", check_plausible=False)
    assert (lift.contact_response, lift.friction_static_ratio, lift.friction_kinetic_ratio) == ("in_solver", 0.5, 0.4)
    assert lift.friction_shear_damping_pa_s_per_m == 1000.0
    assert lift.soft_model == "shell"
    sim = fissure.HostSimulation(lift)
    assert sim.contact_response == "in_solver"
    r = sim.step(sim.scripted_target()[0])
    assert r.part_friction_forces.shape == (2, 3) and r.part_friction_forces.dtype == np.float64
    assert r.friction_force.shape == (3,)
    # Friction is solved only inside the solver: asking for the after-step response is refused as the loader refuses it.
    with pytest.raises(ValueError, match="in_solver"):
        fissure.HostSimulation(lift, contact_response="after_step")


def test_contact_response_override_and_its_refusal(scene):
    assert scene.contact_response == "after_step" and scene.friction_static_ratio == 0.0
    sim = fissure.HostSimulation(scene, contact_response="in_solver")
    assert sim.contact_response == "in_solver" and sim.scene.contact_response == "in_solver"
    r = sim.step(scene.trajectory_start)
    np.testing.assert_array_equal(r.friction_force, [0.0, 0.0, 0.0])
    with pytest.raises(ValueError) as caught:
        fissure.HostSimulation(scene, contact_response="sideways")
    assert str(caught.value) == "contact response 'sideways': expected after_step or in_solver"


def test_every_benchmark_command_has_a_function(fissure_bin):
    listing = subprocess.run([fissure_bin, "bench", "--help"], check=True, capture_output=True, text=True).stdout
    commands = [line.split()[0] for line in listing.split("Subcommands:")[1].splitlines() if line.strip()]
    # `fissure bench all` is the report's orchestrator, not a benchmark; every other one has a function.
    benches = [name for name in commands if name != "all"]
    assert len(benches) >= 9
    for name in benches:
        assert callable(getattr(fissure, f"bench_{name}", None)), f"fissure bench {name} has no fissure.bench_{name}"
    assert "contact_response" in pydoc.render_doc(fissure.bench_collision)


def test_mesh_bench_rows_name_their_sizes():
    result = fissure.bench_mesh(quick=True)
    assert result["quick"] is True
    rows = result["tool_meshes"]
    assert rows and all(row["triangles"] > 0 and row["load_s"] > 0.0 for row in rows)
    assert all(row["tetrahedra"] > 0 for row in result["tet_meshes"])


def test_several_soft_bodies_are_laid_out_body_after_body_and_contacts_name_their_body():
    sim = fissure.HostSimulation(fissure.Scene.load("spatula-fissure"))
    assert sim.soft_body_count == 2
    slices = [sim.soft_body_nodes(b) for b in range(2)]
    assert slices[0].start == 0 and slices[0].stop == slices[1].start and slices[1].stop == sim.soft_node_count
    with pytest.raises(IndexError):
        sim.soft_body_nodes(2)
    nodes = sim.node_positions()
    # The two lobes lie either side of the cleft at x = 0.
    assert nodes[slices[0], 0].max() < 0.0 < nodes[slices[1], 0].min()
    faces = sim.faces()
    assert faces.shape == (sim.soft_face_count, 3)
    sim.settle(0.3)
    seen = set()
    for _ in range(2000):
        r = sim.step(sim.scripted_target()[0])
        c = r.contacts
        assert c["soft_body"].shape == (r.contact_count,) and c["soft_body"].dtype == np.int32
        for body, face in zip(c["soft_body"], c["soft_face"]):
            # soft_face is global: its nodes are rows of the contact's own body.
            corners = faces[face]
            assert slices[body].start <= corners.min() and corners.max() < slices[body].stop
            seen.add(int(body))
        if seen == {0, 1}:
            break
    assert seen == {0, 1}, "the blade in the cleft touches both lobes"


def test_plunge_cells_in_either_response_and_on_either_ball():
    after = fissure.plunge_scene("plate_4mm")
    assert after.contact_response == "after_step"
    in_solver = fissure.plunge_scene("plate_4mm", contact_response="in_solver")
    assert in_solver.contact_response == "in_solver" and in_solver.friction_static_ratio > 0.0
    assert fissure.plunge_scene("plate_4mm", contact_response="in_solver", tool_friction=False).friction_static_ratio == 0.0
    assert fissure.HostSimulation(fissure.plunge_scene("plate_4mm", icosphere_faces=1280)).soft_face_count == 1280
    with pytest.raises(ValueError, match="contact_response 'inside'"):
        fissure.plunge_scene("plate_4mm", contact_response="inside")
    with pytest.raises(ValueError, match="icosphere_faces must be 0"):
        fissure.plunge_scene("plate_4mm", icosphere_faces=100)
    assert fissure.HostSimulation(fissure.plunge_scene("plate_4mm", icosphere_faces=320)).soft_face_count == 320
    cell = fissure.run_plunge_hold("plate_4mm", "paired", 1.0, hold_s=0.05, contact_response="in_solver")
    assert cell["crossed_nodes"] == 0 and cell["inside_nodes"] == 0
    assert cell["hold_force_n"].shape == (50,) and cell["hold"]["mean_n"] > 0.0
