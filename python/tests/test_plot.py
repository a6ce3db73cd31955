"""lieflow.plot (issue 13): the drawn data are the trajectory's (drifts, fields, work–precision
points, box corners turned by the attitude), animations have one frame per saved sample (checked
in a written GIF), and bad input is a typed error."""

import gc
import warnings

import numpy as np
import pytest

import lieflow as lf

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from lieflow import plot  # noqa: E402

M0 = np.array([1.0, 0.5, -0.3])


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")
    with warnings.catch_warnings():      # the animations inspected here, never shown or saved
        warnings.simplefilter("ignore")
        gc.collect()


def spinning(steps=12, every=1):
    rb = lf.RigidBody([1.0, 2.0, 3.0])
    return lf.integrate(rb, 3 * M0, dt=0.05, steps=steps, save_every=every, attitude=np.eye(3))


def test_invariants_draws_the_relative_drifts():
    traj = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.1, steps=200, method="rk4")
    ax = plot.invariants(traj)
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert set(lines) == {"energy", "|M|²", "machine ε"}     # the system's invariant_names
    e = traj.energy()
    expected = np.abs(e - e[0]) / abs(e[0])
    x, y = lines["energy"].get_data()
    np.testing.assert_array_equal(x, traj.t)
    np.testing.assert_allclose(y[1:], expected[1:], rtol=1e-15)
    assert np.isnan(y[0])                    # no drift at t0: left out of the log plot
    assert ax.get_yscale() == "log"
    # a batch: the largest drift over the members
    batch = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), np.stack([M0, 2 * M0]), dt=0.1,
                         steps=50, method="rk4")
    _, ax = plt.subplots()
    assert plot.invariants(batch, ax=ax) is ax
    e = batch.energy()
    d = (np.abs(e - e[:, :1]) / np.abs(e[:, :1])).max(axis=0)
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata()[1:], d[1:], rtol=1e-15)
    assert "max over 2 members" in ax.get_title()


def test_legends_name_the_invariants_and_cover_no_data():
    top = lf.HeavyTop([1.0, 2.0, 3.0], 0.7)
    traj = lf.integrate(top, (M0, [0.0, 0.6, 0.8]), dt=0.1, steps=100, method="rk4")
    for ax in [plot.invariants(traj), plot.states(traj)[0],
               plot.work_precision({"a": ([1e-3, 1e-6], [1.0, 2.0])})]:
        ax.figure.canvas.draw()
        legend = ax.get_legend().get_window_extent()
        assert legend.x0 >= ax.get_window_extent().x1          # beside the axes, not on them
        # ... and inside the figure (the constrained layout made room for it)
        assert legend.x1 <= ax.figure.bbox.x1 + 1
    labels = [t.get_text() for t in plot.invariants(traj).get_legend().get_texts()]
    assert labels == ["energy", "|Γ|²", "M·Γ", "machine ε"]


def test_states_one_panel_per_field():
    hv = lf.HeavyTop([1.0, 2.0, 3.0], 0.7)
    traj = lf.integrate(hv, (M0, [0.0, 0.6, 0.8]), dt=0.01, steps=30)
    axes = plot.states(traj)
    assert len(axes) == 2 and [a.get_ylabel() for a in axes] == ["M", "Gamma"]
    np.testing.assert_array_equal(axes[1].get_lines()[2].get_ydata(), traj.Gamma[:, 2])
    prb = lf.PseudoRigidBody(2, potential=lf.potentials.Harmonic(1.0))
    x = np.diag([1.2, 0.9])
    traj = lf.integrate(prb, np.stack([(x, 0 * x)[0].ravel().tolist() + [0.0] * 4] * 2),
                        dt=0.01, steps=10)
    axes = plot.states(traj, fields=["X"], member=1)
    assert len(axes) == 1 and len(axes[0].get_lines()) == 4
    np.testing.assert_array_equal(axes[0].get_lines()[3].get_ydata(), traj.X[1, :, 1, 1])
    with pytest.raises(lf.InvalidArgumentError, match="fields"):
        plot.states(traj, fields=["Q"])
    with pytest.raises(lf.InvalidArgumentError, match="axes"):
        plot.states(traj, axes=[])


def test_work_precision():
    ax = plot.work_precision({"a": ([1e-3, 1e-6], [0.2, 0.1]), "b": ((1e-4,), (0.3,))})
    x, y = ax.get_lines()[0].get_data()
    np.testing.assert_array_equal(x, [1e-6, 1e-3])       # sorted by error
    np.testing.assert_array_equal(y, [0.1, 0.2])
    assert ax.get_xscale() == ax.get_yscale() == "log"
    for bad in ({}, [1, 2], {"a": ([1, 2], [1])}, {"a": "xy"}):
        with pytest.raises(lf.InvalidArgumentError, match="results"):
            plot.work_precision(bad)


def test_animate_rigid_body_writes_one_gif_frame_per_sample(tmp_path):
    from PIL import Image

    traj = spinning(steps=12, every=2)
    path = tmp_path / "body.gif"
    anim = plot.animate(traj, path, interval=50)
    with Image.open(path) as gif:
        assert gif.n_frames == len(traj) == 7
    # the box is the body's: at frame i its corners are R_i times those of frame 0
    anim._func(0)
    box = [c for c in anim._fig.axes[0].collections][0]
    v0 = np.array(box._faces, copy=True)
    anim._func(4)
    np.testing.assert_allclose(box._faces, v0 @ traj.attitude[4].T, atol=1e-12)


def test_animate_heavy_top_pseudo_rigid_and_disks(tmp_path):
    from PIL import Image

    hv = lf.HeavyTop([1.0, 1.0, 0.5], 0.7)
    R0 = lf.lie.so3_exp([0.4, 0.0, 0.0])
    traj = lf.integrate(hv, hv.state([0.0, 0.0, 3.0], attitude=R0), dt=0.05, steps=4,
                        attitude=R0)
    anim = plot.animate(traj)
    rod = anim._fig.axes[0].get_lines()[1]
    anim._func(3)
    np.testing.assert_allclose(np.array(rod.get_data_3d())[:, 1], traj.attitude[3] @ hv.chi)
    for n in (2, 3):
        prb = lf.PseudoRigidBody(n, potential=lf.potentials.Harmonic(1.0))
        x = np.diag([1.3, 1.0, 0.8][:n])
        traj = lf.integrate(prb, (x, lf.lie.hat_n([0.5, 0.1, 0.2][: n * (n - 1) // 2]) @ x),
                            dt=0.1, steps=5)
        path = tmp_path / f"prb{n}.gif"
        plot.animate(traj, path)
        with Image.open(path) as gif:
            assert gif.n_frames == 6
    disks = lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6)
    traj = lf.integrate(disks, disks.state([0.3, -1.1], [0.7, 0.2]), dt=0.05, steps=40,
                        save_every=4)
    anim = plot.animate(traj, every=2)
    anim._init_draw()
    artists = anim._func(5)
    # The disks' seven artists and the time stamp of frame 5 (sample 10).
    assert len(artists) == 8 and artists[-1].get_text() == f"t = {traj.t[10]:.4g}"


def test_animations_carry_a_time_stamp_and_axis_labels():
    prb = lf.PseudoRigidBody(3, potential=lf.potentials.Harmonic(1.0))
    x = np.diag([1.3, 1.0, 0.8])
    traj = lf.integrate(prb, (x, lf.lie.hat([0.5, 0.1, 0.2]) @ x), dt=0.1, steps=6)
    body = lf.RigidBody([1.0, 2.0, 3.0])
    turning = lf.integrate(body, [1.0, 0.5, -0.3], dt=0.1, steps=6, attitude=np.eye(3))
    for t in (traj, turning):
        anim = plot.animate(t, every=3)
        ax = anim._fig.axes[0]
        assert ax.get_xlabel() == "x" and ax.get_ylabel() == "y"
        stamp = anim._func(2)[-1]
        assert stamp.get_text() == f"t = {t.t[6]:.4g}"
        plt.close(anim._fig)


def test_animate_rolling_spheres_and_tangent_top():
    spheres = lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5,
                                np.diag([1.0, 1.2, 1.4]), np.diag([2.0, 2.2, 2.4]))
    z = spheres.state(np.eye(3), np.eye(3), [0.0, 0.0, 1.0], [1.1, -0.6, 0.8], [-0.4, 0.9, 0.5])
    traj = lf.integrate(spheres, z, dt=0.01, steps=30, save_every=10)
    anim = plot.animate(traj)
    assert anim._save_count == len(traj) == 4
    anim._func(2)
    spoke = anim._fig.axes[0].get_lines()[1]
    np.testing.assert_allclose(np.array(spoke.get_data_3d()).T,
                               [spheres.centres(traj.states[2])[1],
                                spheres.centres_of_mass(traj.states[2])[1]])
    top = lf.TangentTop(lf.surfaces.Sphere(1.0), 1.0, 0.5)
    traj = lf.integrate(top, top.state([0.3, 0.2], 0.1, [0.4, -0.2], 0.3), dt=0.01, steps=40,
                        save_every=10)
    anim = plot.animate(traj)
    anim._func(3)
    c, e1 = top.ambient_frame(traj.states[3])[:2]
    seg = np.array(anim._fig.axes[0].get_lines()[1].get_data_3d()).T
    np.testing.assert_allclose(seg[0], c)
    direction = seg[1] - seg[0]
    np.testing.assert_allclose(direction / np.linalg.norm(direction), e1, atol=1e-12)
    flat = lf.TangentTop(lf.surfaces.HyperbolicPlane(), 1.0, 0.5)
    traj = lf.integrate(flat, flat.state([0.3, 1.2], 0.1, [0.4, -0.2], 0.3), dt=0.01, steps=3)
    with pytest.raises(lf.InvalidArgumentError, match="embedding"):
        plot.animate(traj)


def test_animate_errors(tmp_path):
    traj = spinning()
    no_attitude = lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), M0, dt=0.1, steps=3)
    with pytest.raises(lf.InvalidArgumentError, match="attitude=R0"):
        plot.animate(no_attitude)
    with pytest.raises(lf.InvalidArgumentError, match="no animation for Pendulum"):
        plot.animate(lf.integrate(lf.Pendulum(1.0, 1.0, 9.81), [1.0, 0.0], dt=0.1, steps=3))
    for every in (0, 1.5, True, 2**63, 2**70):      # counts are 64-bit, as everywhere
        with pytest.raises(lf.InvalidArgumentError, match=r"every: expected an integer in \[1, "):
            plot.animate(traj, every=every)
    anims = [plot.animate(traj, every=e) for e in (2, np.int64(2), 2**63 - 1)]
    for a in anims:
        a._init_draw()
    assert [len(list(a.new_frame_seq())) for a in anims] == [7, 7, 1]
    with pytest.raises(lf.InvalidArgumentError, match=".gif or .mp4"):
        plot.animate(traj, tmp_path / "a.avi")
    assert not (tmp_path / "a.avi").exists()
