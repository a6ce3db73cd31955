"""The one table of valid example calls: every public callable of lieflow with a valid value and
a kind for each of its arguments.

A spec is (id, target, args). The target names the callable: ``"lie.so3_exp"`` (a module
function), ``"RigidBody"`` (a constructor), ``"@rb.angular_velocity"`` (a method of the receiver
``rb`` of RECEIVERS) or ``"integrate"``. Each argument has a kind that says which bad values of
the catalogue apply to it (see catalogue.py):

  vec     numeric array whose trailing shape is fixed (may take leading batch axes)
  bcast   numeric array or scalar that broadcasts (elliptic arguments, times)
  mat     general square matrix          gl     matrix of GL+(n) (det > 0)
  skew    so(n) matrix                   rot    rotation matrix (an attitude, R in SO(n))
  se3     4x4 homogeneous SE(3) matrix   float  physical scalar     int  integer count/size
  str     option name                    bool   flag                obj  a lieflow object
  fn      a Python callable handed to native code (potentials, surfaces)
  path    a file path (only non-path values are fuzzed: a bad string would write a file)

Flags: ``positive`` (zero/negative must be refused), ``opt`` (None is a valid value),
``kw`` (passed by keyword), ``complex_ok`` (complex numbers are a valid spelling).

Values may be ``Lazy(f)``: computed from the imported ``lieflow`` module in the process that
makes the call (states of systems, potentials, surfaces).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np


@dataclass(frozen=True)
class Lazy:
    make: Callable[[Any], Any]


@dataclass
class Arg:
    name: str
    value: Any
    kind: str
    kw: bool = False
    opt: bool = False
    positive: bool = False
    complex_ok: bool = False


@dataclass
class Spec:
    id: str
    target: str
    args: list = field(default_factory=list)
    module: str = ""          # lie, pseudo_rigid, potentials, surfaces, elliptic, systems, integrate
    slow: bool = False        # seconds per call: fewer cases in the quick tier

    def __post_init__(self):
        if not self.module:
            head = self.target.lstrip("@").split(".")[0]
            self.module = {"lie": "lie", "pseudo_rigid": "pseudo_rigid", "potentials": "potentials",
                           "surfaces": "surfaces", "spaces": "spaces", "elliptic": "elliptic",
                           "ellipsoids": "pseudo_rigid", "continuation": "pseudo_rigid",
                           "integrate": "integrate"}.get(head, "systems")
            if head in RECEIVER_MODULE:
                self.module = RECEIVER_MODULE[head]


def _maclaurin_branch(lf):
    """A short Maclaurin branch through the Jacobi branch point (no stability: fast)."""
    return lf.continuation.follow(lf.ellipsoids.maclaurin(0.8), "e", 0.815, stability=False)


def _branch_point(lf):
    return next(s for s in _maclaurin_branch(lf).special_points if s.kind == "branch")


def A(name, value, kind, **flags):
    return Arg(name, value, kind, **flags)


# --- valid values (numpy only: no lieflow needed to build the table) ---

def rodrigues(w):
    w = np.asarray(w, float)
    th = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / th
    return np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * k @ k


def skew3(a, b, c):
    """so(3) matrix in the e_ij basis: e_12 a + e_13 b + e_23 c."""
    return np.array([[0.0, a, b], [-a, 0.0, c], [-b, -c, 0.0]])


W3 = np.array([0.3, -0.2, 0.5])
R3 = rodrigues(W3)
R3B = rodrigues([-0.1, 0.4, 0.2])
XI = skew3(0.4, 0.1, 0.2)
ETA = skew3(-0.2, 0.3, 0.1)
X3 = np.array([[1.3, 0.1, 0.0], [0.05, 1.0, 0.1], [0.0, 0.2, 0.7]])      # GL+, distinct s.v.
V3 = np.array([[0.1, -0.2, 0.3], [0.0, 0.4, -0.1], [0.2, 0.1, 0.05]])
G4 = np.block([[R3, np.array([[0.3], [-0.1], [0.2]])], [np.zeros((1, 3)), np.ones((1, 1))]])
H4 = np.block([[R3B, np.array([[-0.2], [0.4], [0.1]])], [np.zeros((1, 3)), np.ones((1, 1))]])
SE3XI = np.array([0.3, -0.2, 0.5, 0.1, 0.2, -0.3])
A3 = np.array([1.3, 1.0, 0.7])
SKEW4 = np.triu(np.arange(16.0).reshape(4, 4) / 20, 1) - np.triu(np.arange(16.0).reshape(4, 4) / 20, 1).T
M3 = np.array([1.0, 0.5, -0.3])
I_SPH1 = np.array([[0.40, 0.05, -0.02], [0.05, 0.30, 0.04], [-0.02, 0.04, 0.25]])
I_SPH2 = np.array([[0.90, -0.10, 0.05], [-0.10, 1.10, 0.08], [0.05, 0.08, 0.70]])
U_SPH = np.array([0.2, 0.9, -0.3]) / np.linalg.norm([0.2, 0.9, -0.3])
FT_X = np.array([0.9, 0.0, 1.2, 0.0])                 # on Sphere(3, radius=1.5)
FT_V = np.array([0.0, 0.5, 0.0, -0.4])                # tangent there


# --- user callables (module level: native code calls them; they also pickle) ---

def u_value(X):
    return 0.5 * float(np.sum(np.asarray(X) ** 2))


def u_gradient(X):
    return np.asarray(X, float)


def u_hessian(X, V):
    return np.asarray(V, float)


def torus_r(s):
    return 2.0 + 0.7 * np.cos(s), -0.7 * np.sin(s), -0.7 * np.cos(s), 0.7 * np.sin(s)


def torus_z(s):
    return 0.7 * np.sin(s), 0.7 * np.cos(s), -0.7 * np.sin(s), -0.7 * np.cos(s)


def saddle(x, y):
    return 0.5 * (0.8 * x * x - 0.5 * y * y), 0.8 * x, -0.5 * y, 0.8, 0.0, -0.5, 0, 0, 0, 0


def sphere_metric(t, p):
    return [[1.0, 0.0], [0.0, math.sin(t) ** 2]]


def sphere_frame(t, p):
    return [[1.0, 0.0], [0.0, 1.0 / math.sin(t)]]


def inside(t, p):
    return 0.0 < t < math.pi


def conformal_metric(x1, x2, x3):
    s = 1.0 + 0.1 * (x1 * x1 + x2 * x2 + x3 * x3)
    return [[s * s, 0.0, 0.0], [0.0, s * s, 0.0], [0.0, 0.0, s * s]]


def conformal_frame(x1, x2, x3):
    s = 1.0 + 0.1 * (x1 * x1 + x2 * x2 + x3 * x3)
    return [[1.0 / s, 0.0, 0.0], [0.0, 1.0 / s, 0.0], [0.0, 0.0, 1.0 / s]]


def ball(x1, x2, x3):
    return x1 * x1 + x2 * x2 + x3 * x3 < 25.0


class _Parts(list):
    """A list that the harness's mutation check compares with itself (its deepcopy is itself):
    Trajectory has no value equality (== is identity), so a copy would always differ."""

    def __deepcopy__(self, memo):
        return self


def _two_runs(lf):
    """A run of the rigid body and its continuation (Trajectory.concatenate)."""
    body = lf.RigidBody([1.0, 2.0, 3.0])
    a = lf.integrate(body, [1.0, 0.5, -0.3], dt=0.01, steps=10)
    return _Parts([a, lf.integrate(body, a.final_state, dt=0.01, steps=10, t0=a.t_final)])


def _shared(traj):
    """A trajectory the harness's mutation check compares with itself (see _Parts)."""
    traj.__deepcopy__ = lambda memo: traj
    return traj


def _scratch_path(name):
    """A path in a temporary directory of this process (removed at exit)."""
    import atexit
    import os
    import shutil
    import tempfile

    d = tempfile.mkdtemp(prefix="lieflow-fuzz-")
    atexit.register(shutil.rmtree, d, True)
    return os.path.join(d, name)


def _saved_run(lf):
    """A NetCDF file of a short rigid-body run (lf.load)."""
    path = _scratch_path("run.nc")
    lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), [1.0, 0.5, -0.3], dt=0.01, steps=10).save(path)
    return path


def _turning_box(lf):
    """A rigid-body run with its attitude (lieflow.plot.animate draws the box)."""
    return _shared(lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), [3.0, 1.5, -0.9], dt=0.05,
                                steps=4, attitude=np.eye(3)))


def section_gamma1(state):
    """A Poincaré section of the heavy top (lf.poincare_section): Gamma_1 = 0."""
    return float(state[3])


def event_m2(t, state):
    """An event function of the rigid body (lf.integrate(events=...)): M₂, zero at t ≈ 1.6."""
    return state[1]


def riemann_lagrangian(Q, N):
    """The free body's L(Q, N) = tr(N^T Q^-1 N)/2 (001 (3.18))."""
    return 0.5 * float(np.trace(N.T @ np.linalg.solve(Q, N)))


def _svk(lf):
    return lf.potentials.SaintVenantKirchhoff(1.0, 2.0)


# --- receivers: the objects whose methods are fuzzed (built in the calling process) ---

RECEIVERS: dict[str, Callable[[Any], Any]] = {
    "rb": lambda lf: lf.RigidBody([1.0, 2.0, 3.0]),
    "grb": lambda lf: lf.GeneralizedRigidBody([1.0, 2.0, 3.0, 4.0]),
    "ht": lambda lf: lf.HeavyTop([1.0, 2.0, 3.0], 0.7),
    "sp": lambda lf: lf.SphericalPendulum(2.0, 1.5, 9.81),
    "pend": lambda lf: lf.Pendulum(1.0, 1.0, 9.81),
    "spart": lambda lf: lf.SphereParticle(2.0, 1.5, 9.81),
    "disk": lambda lf: lf.RollingDisk(1.0, 0.5, 0.125, 0.0625, spring=0.4),
    "prb": lambda lf: lf.PseudoRigidBody(3, _svk(lf)),
    "iprb": lambda lf: lf.PseudoRigidBody(3, _svk(lf), incompressible=True),
    "rrb": lambda lf: lf.pseudo_rigid.RightReduced(3, _svk(lf), reconstruct=True),
    "ft": lambda lf: lf.FrameTop(lf.spaces.Sphere(3, radius=1.5), 1.3, A3),
    "s3": lambda lf: lf.spaces.Sphere(3, radius=1.5),
    "chart": lambda lf: lf.spaces.Riemannian(conformal_metric, conformal_frame, ball),
    "ftc": lambda lf: lf.FrameTop(lf.spaces.Riemannian(conformal_metric, conformal_frame), 1.3, A3),
    "rtt": lambda lf: lf.RelativisticTangentTop(1.0, 0.2, lf.surfaces.Sphere(1.0)),
    "wft": lambda lf: lf.WeakFieldTop(1.0, 1e-3, gm=1e-4),
    "sft": lambda lf: lf.StaticFieldTop(1.0, 0.2, gm=0.15),
    "tt": lambda lf: lf.TangentTop(lf.surfaces.Sphere(1.0), 1.0, 0.5),
    "cp": lambda lf: lf.TangentTop(lf.surfaces.Sphere(1.0), 1.0, 0.5).magnetic_analogue(0.7),
    "rds": lambda lf: lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8, 0.6),
    "rdeq": lambda lf: lf.RollingDisks(1.0, 0.7, 0.3 + 0.1j, [-0.2, 0.25], 1.0, 1.5, 0.8,
                                       0.6).relative_equilibria()[0],
    "releq": lambda lf: lf.pseudo_rigid.relative_equilibria(
        _svk(lf), velocities=(0.5 * skew3(1, 0, 0), 0.9 * skew3(1, 0, 0)), bounds=(0.05, 3.0),
        starts=3)[0],
    "run": lambda lf: lf.RigidBody([1.0, 2.0, 3.0])._start(
        np.array([[1.0, 0.5, -0.3]]), None, 0.01, None, 1),
    "traj": lambda lf: lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), [1.0, 0.5, -0.3], dt=0.01,
                                    steps=10),
    "straj": lambda lf: lf.integrate(lf.RigidBody([1.0, 2.0, 3.0]), [1.0, 0.5, -0.3], dt=0.01,
                                     steps=10, sensitivity=True),
    "rsph": lambda lf: lf.RollingSpheres(0.7, 1.3, [0.1, -0.2, 0.15], [-0.3, 0.2, 0.4], 2.0, 3.5,
                                         I_SPH1, I_SPH2),
    "harmonic": lambda lf: lf.potentials.Harmonic(1.3),
    "svk": _svk,
    "volumetric": lambda lf: lf.potentials.Volumetric(0.5, 1.4),
    "stretch": lambda lf: lf.potentials.Stretch(1.1),
    "selfgrav": lambda lf: lf.potentials.SelfGravity(1.0, 1.0),
    "branch": lambda lf: _maclaurin_branch(lf),
    "porb": lambda lf: _free_body_orbit(lf),
    "pbranch": lambda lf: lf.continuation.periodic_family(lf.RigidBody([1.0, 2.0, 3.0]),
                                                           _free_body_orbit(lf), max_points=3),
    "zero": lambda lf: lf.potentials.Zero(),
    "sum": lambda lf: lf.potentials.Harmonic(1.0) + _svk(lf),
    "callable": lambda lf: lf.potentials.Callable(u_value, u_gradient, u_hessian),
    "plane": lambda lf: lf.surfaces.Plane(),
    "sphere": lambda lf: lf.surfaces.Sphere(1.0),
    "hyp": lambda lf: lf.surfaces.HyperbolicPlane(),
    "torus": lambda lf: lf.surfaces.Torus(2.0, 0.7),
    "quadric": lambda lf: lf.surfaces.Quadric(0.8, -0.5),
    "revolution": lambda lf: lf.surfaces.Revolution(torus_r, torus_z, (-math.pi, math.pi)),
    "graph": lambda lf: lf.surfaces.Graph(saddle),
    "metric": lambda lf: lf.surfaces.MetricSurface(sphere_metric, sphere_frame, inside),
}
# Receivers with a state of their own (a run advances): built afresh for every call.
FRESH = {"run"}
RECEIVER_MODULE = {**{k: "potentials" for k in ("harmonic", "svk", "volumetric", "stretch", "zero",
                                                  "sum", "callable", "selfgrav")},
                   **{k: "surfaces" for k in ("plane", "sphere", "hyp", "torus", "quadric",
                                              "revolution", "graph", "metric")},
                   "releq": "pseudo_rigid", "branch": "pseudo_rigid", "s3": "spaces",
                   "porb": "integrate", "pbranch": "integrate",
                   "chart": "spaces"}
# The point of each surface's chart used for its methods.
SURFACE_POINT = {"plane": [0.2, -0.1], "sphere": [1.0, 0.3], "hyp": [0.1, 1.0],
                 "torus": [0.9, 0.4], "quadric": [0.3, -0.4], "revolution": [0.9, 0.4],
                 "graph": [0.3, -0.4], "metric": [1.2, 0.4]}


def state_of(key):
    """A valid state of receiver `key` (Lazy)."""
    makers = {
        "rb": lambda lf, s: M3.copy(),
        "grb": lambda lf, s: np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.6]),
        "ht": lambda lf, s: np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8]),
        "sp": lambda lf, s: s.state_from_spherical(0.8, 0.1, 0.3, 1.2),
        "pend": lambda lf, s: np.array([0.4, 0.1]),
        "spart": lambda lf, s: s.from_spherical(
            lf.SphericalPendulum(2.0, 1.5, 9.81).state_from_spherical(0.8, 0.1, 0.3, 1.2)),
        "disk": lambda lf, s: np.asarray(s.state([0.1, -0.2, 0.3, 0.7], 2.0, 0.5)),
        "prb": lambda lf, s: np.concatenate([X3.ravel(), V3.ravel()]),
        "iprb": lambda lf, s: np.concatenate([X3.ravel(),
                                              s.project_momentum(X3, V3).ravel()]),
        "rrb": lambda lf, s: s.reduce(X3, V3),
        "ft": lambda lf, s: s.state(FT_X, R3, FT_V, W3),
        "ftc": lambda lf, s: s.state(FT_X[:3], R3, FT_V[:3], W3),
        "rtt": lambda lf, s: np.asarray(s.state([1.2, 0.3], 0.5, [0.3, 0.4], 2.0)),
        "wft": lambda lf, s: np.asarray(s.state([1.0, 0.5], 0.1, [0.1, 0.2], 0.3)),
        "sft": lambda lf, s: np.asarray(s.state([1.0, 0.0], 0.3, [0.05, 0.38], 1.2)),
        "tt": lambda lf, s: np.asarray(s.state([1.0, 0.3], 0.2, [0.1, 0.3], 1.5)),
        "cp": lambda lf, s: np.asarray(s.state([1.0, 0.3], [0.1, 0.3])),
        "rds": lambda lf, s: np.asarray(s.state([0.3, -1.1], [0.7, 0.2])),
        "rsph": lambda lf, s: np.asarray(s.state(R3, R3B, U_SPH, [1.1, -0.6, 0.8], [-0.4, 0.9, 0.5])),
    }
    return Lazy(lambda lf: makers[key](lf, RECEIVERS[key](lf)))


SYSTEMS = ["rb", "grb", "ht", "sp", "pend", "spart", "disk", "prb", "iprb", "rrb", "ft", "rtt", "wft",
           "sft", "tt", "cp",
           "rds", "rsph"]
CONSTRUCTORS = {  # class name -> receiver key built by it
    "RigidBody": "rb", "GeneralizedRigidBody": "grb", "HeavyTop": "ht", "SphericalPendulum": "sp",
    "Pendulum": "pend", "SphereParticle": "spart", "RollingDisk": "disk", "PseudoRigidBody": "prb",
    "RelativisticTangentTop": "rtt", "WeakFieldTop": "wft", "StaticFieldTop": "sft",
    "TangentTop": "tt",
    "ChargedParticle": "cp", "RollingDisks": "rds", "RollingSpheres": "rsph",
    "RightReduced": "rrb", "FrameTop": "ft",
}


# --- user-defined systems (issue 15): lf.Canonical, lf.Separable, lf.LiePoisson ---
# Their callables are "obj" arguments of the constructors (a constructor does not call them; the
# bad return values of the "fn" kind are tested through runs in test_user_systems.py).

def user_h(q, p):
    return 0.5 * float(p @ p + q @ q)


def user_grad(q, p):
    return q, p


def user_ddh(q, p, dq, dp):
    return dq, dp


def user_u(q):
    return 0.5 * float(q @ q)


def user_du(q):
    return np.asarray(q, float)


def user_ddu(q, v):
    return np.asarray(v, float)


def user_lp_h(mu):
    return 0.5 * float(mu @ (mu / A3))


def user_lp_grad(mu):
    return np.asarray(mu, float) / A3


def user_lp_hess(mu, dmu):
    return np.asarray(dmu, float) / A3


def user_casimir(mu):
    return float(mu @ mu)


KIRCHHOFF = np.diag([1.0, 0.7, 0.4, 2.0, 1.5, 1.2])
KIRCHHOFF[0, 4] = KIRCHHOFF[4, 0] = 0.1

def user_ep_l(w, g):
    return 0.5 * float(w @ (A3 * w)) - 0.7 * float(g[2])


def user_ep_dl(w, g):
    return A3 * w, np.array([0.0, 0.0, -0.7])


RECEIVERS.update({
    "uep": lambda lf: lf.EulerPoincare("so3", user_ep_l, gradient=user_ep_dl, action="vector"),
    "ucan": lambda lf: lf.Canonical(user_h, user_grad, 2),
    "usep": lambda lf: lf.Separable([1.0, 2.0], user_u, user_du),
    "ulp": lambda lf: lf.LiePoisson("so3", user_lp_h, user_lp_grad, [user_casimir]),
    "ulpq": lambda lf: lf.LiePoisson("se3", KIRCHHOFF),
})
CONSTRUCTORS.update({"Canonical": "ucan", "Separable": "usep", "LiePoisson": "ulp",
                     "EulerPoincare": "uep"})
USER_STATES = {"ucan": np.array([0.3, -0.2, 0.1, 0.4]), "usep": np.array([0.3, -0.2, 0.1, 0.4]),
               "ulp": M3, "ulpq": np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8]),
               "uep": np.array([1.0, 0.5, -0.3, 0.0, 0.6, 0.8])}


def user_specs(add):
    """The specs of the user-defined systems (issue 15)."""
    add("Canonical", "Canonical", A("hamiltonian", user_h, "obj"),
        A("gradient", user_grad, "obj", opt=True), A("dof", 2, "int", positive=True))
    add("Canonical[hessian]", "Canonical", A("hamiltonian", user_h, "obj"),
        A("gradient", user_grad, "obj", opt=True), A("dof", 2, "int", positive=True),
        A("hessian", user_ddh, "obj", kw=True, opt=True))
    add("Separable", "Separable", A("mass", 1.5, "float", positive=True),
        A("potential", user_u, "obj"), A("gradient", user_du, "obj", opt=True),
        A("dof", 1, "int", kw=True, positive=True))
    add("Separable[matrix]", "Separable", A("mass", I_SPH2, "mat"),
        A("potential", user_u, "obj"), A("gradient", user_du, "obj", opt=True))
    add("Separable[hessian]", "Separable", A("mass", I_SPH2, "mat"),
        A("potential", user_u, "obj"), A("gradient", user_du, "obj", opt=True),
        A("dof", None, "obj", opt=True), A("hessian", user_ddu, "obj", kw=True, opt=True))
    add("LiePoisson", "LiePoisson", A("algebra", "so3", "str"), A("hamiltonian", user_lp_h, "obj"),
        A("gradient", user_lp_grad, "obj", opt=True),
        A("casimirs", [user_casimir], "obj", opt=True))
    add("LiePoisson[hessian]", "LiePoisson", A("algebra", "so3", "str"),
        A("hamiltonian", user_lp_h, "obj"), A("gradient", user_lp_grad, "obj", opt=True),
        A("hessian", user_lp_hess, "obj", kw=True, opt=True))
    add("LiePoisson[quadratic]", "LiePoisson", A("algebra", "se3", "str"),
        A("hamiltonian", KIRCHHOFF, "mat"))
    add("LiePoisson[so(n)]", "LiePoisson", A("algebra", ("so", 4), "obj"),
        A("hamiltonian", np.eye(6), "mat"))
    add("LiePoisson[constants]", "LiePoisson", A("algebra", Lazy(
        lambda lf: lf.LiePoisson(("so", 3), np.eye(3)).structure_constants()), "vec"),
        A("hamiltonian", np.diag(A3), "mat"))
    for key, st in USER_STATES.items():
        for f in ("energy", "invariants", "casimirs"):
            add(f"{key}.{f}", f"@{key}.{f}", A("states", st, "vec"))
        add(f"{key}.methods", f"@{key}.methods")
        add(f"integrate[{key}]", "integrate", A("system", lazy_recv(key), "obj"),
            A("state0", st, "vec"), A("dt", 0.01, "float", kw=True),
            A("steps", 10, "int", kw=True), A("method", None, "str", kw=True, opt=True))
    add("EulerPoincare", "EulerPoincare", A("algebra", "so3", "str"),
        A("lagrangian", user_ep_l, "obj", opt=True),
        A("gradient", user_ep_dl, "obj", kw=True, opt=True),
        A("action", "vector", "str", kw=True, opt=True))
    add("EulerPoincare[inertia]", "EulerPoincare", A("algebra", "so3", "str"),
        A("inertia", np.diag(A3), "mat", kw=True))
    add("uep.state", "@uep.state", A("xi", M3, "vec"), A("a", np.array([0.0, 0.6, 0.8]), "vec"))
    add("uep.velocity", "@uep.velocity", A("state", USER_STATES["uep"], "vec"))
    add("uep.noether", "@uep.noether", A("states", USER_STATES["uep"], "vec"),
        A("g", np.eye(3), "mat"))
    add("uep.diamond", "@uep.diamond", A("b", M3, "vec"), A("a", np.array([0.0, 0.6, 0.8]), "vec"))
    add("ulpq.structure_constants", "@ulpq.structure_constants")
    # The inertia of a body (000 §3.1, (4.1)).
    for f in ("inertia_tensor", "mass_matrix"):
        add(f, f, A("masses", np.array([1.0, 0.5, 2.0]), "vec"),
            A("positions", np.array([[0.3, -0.2, 0.5], [1.0, 0.4, -0.7], [-0.6, 0.8, 0.1]]),
              "mat"))
        add(f"{f}[solid]", f, A("shape", "ellipsoid", "str", kw=True),
            A("mass", 2.0, "float", kw=True), A("semi_axes", A3, "vec", kw=True))
    add("spatial_inertia", "spatial_inertia", A("R", R3, "rot"), A("inertia", A3, "vec"))
    add("ulp.structure_constants", "@ulp.structure_constants")


# --- forced systems (issue 15): lf.Forced with a torque, damping or dissipation ---

def forced_torque(t, z):
    return np.array([0.3, -0.2, 0.1 * np.cos(t)])


RECEIVERS.update({
    "frc": lambda lf: lf.Forced(lf.RigidBody([1.0, 2.0, 3.0]), forced_torque),
    "fdamp": lambda lf: lf.Forced(lf.Pendulum(1.0, 1.0, 9.81), damping=0.3),
    "fdiss": lambda lf: lf.Forced(lf.RigidBody([1.0, 2.0, 3.0]), dissipation=0.5),
})
CONSTRUCTORS.update({"Forced": "frc"})
FORCED_STATES = {"frc": M3, "fdamp": np.array([0.4, 0.1]), "fdiss": M3}


def forced_specs(add):
    """The specs of lf.Forced (issue 15)."""
    add("Forced", "Forced", A("system", lazy_recv("rb"), "obj"),
        A("force", forced_torque, "obj", opt=True), A("block", "M", "str", opt=True),
        A("depends_on_block", False, "obj", opt=True))
    add("Forced[damping]", "Forced", A("system", lazy_recv("pend"), "obj"),
        A("damping", 0.3, "float", kw=True))
    add("Forced[dissipation]", "Forced", A("system", lazy_recv("rb"), "obj"),
        A("dissipation", 0.5, "float", kw=True))
    for key, st in FORCED_STATES.items():
        for f in ("energy", "invariants"):
            add(f"{key}.{f}", f"@{key}.{f}", A("states", st, "vec"))
        add(f"{key}.methods", f"@{key}.methods")
        add(f"integrate[{key}]", "integrate", A("system", lazy_recv(key), "obj"),
            A("state0", st, "vec"), A("dt", 0.01, "float", kw=True),
            A("steps", 10, "int", kw=True), A("method", None, "str", kw=True, opt=True))


# --- lieflow.ensemble: Dask ensembles and sweeps (fuzzed when dask and xarray are installed) ---

def _has_dask():
    import importlib.util

    return all(importlib.util.find_spec(m) is not None for m in ("dask", "xarray"))


def ensemble_body(i3):
    """make_system of the lf.ensemble.sweep spec: a rigid body with I3 = i3."""
    import lieflow

    return lieflow.RigidBody([1.0, 2.0, i3])


def ensemble_specs(add):
    """lf.ensemble.integrate / sweep (the lazy Dataset is computed by the harness on Dask's
    synchronous scheduler, see core._exercise) and default_chunks. Their arguments are checked
    before any task is made, with lf.integrate's helpers and errors."""
    if not _has_dask():
        return
    batch = np.array([[1.0, 0.5, -0.3], [0.2, -0.4, 0.9]])
    add("ensemble.integrate[rb]", "use:ensemble.integrate", A("system", lazy_recv("rb"), "obj"),
        A("state0", batch, "vec"), A("dt", 0.01, "float", positive=True),
        A("steps", 12, "int", positive=True), A("method", "splitting4", "str", opt=True),
        A("save_every", 5, "int", positive=True), A("chunks", 1, "int", kw=True, opt=True,
                                                     positive=True),
        A("t0", 0.5, "float", kw=True), module="integrate")
    add("ensemble.integrate[rb,attitude]", "use:ensemble.integrate",
        A("system", lazy_recv("rb"), "obj"), A("state0", batch, "vec"), A("dt", 0.01, "float"),
        A("steps", 10, "int"), A("attitude", R3, "rot", kw=True, opt=True), module="integrate")
    add("ensemble.sweep", "use:ensemble.sweep", A("make_system", ensemble_body, "fn"),
        A("params", [2.5, 3.5], "obj"), A("state0", M3.copy(), "vec"),
        A("dt", 0.01, "float", positive=True), A("steps", 10, "int", positive=True),
        A("method", None, "str", opt=True), A("save_every", 3, "int", positive=True),
        A("t0", 0.0, "float", kw=True), module="integrate")
    add("ensemble.default_chunks", "ensemble.default_chunks", A("members", 1000, "int"),
        A("cores", 2, "int", kw=True, opt=True, positive=True), module="integrate")


def _scipy_rotation(lf):
    """A scipy Rotation of two rotations (the argument of lf.lie.from_scipy)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(np.stack([R3, R3B]))


def _free_body_orbit(lf):
    """A periodic orbit of the free rigid body (lf.periodic_orbit, the exact flow)."""
    return lf.periodic_orbit(lf.RigidBody([1.0, 2.0, 3.0]), [1.0, 0.3, 0.2], 10.86,
                             method="exact", dt=2.0)


def lazy_recv(key):
    return Lazy(lambda lf: RECEIVERS[key](lf))


def build_specs() -> list[Spec]:
    S: list[Spec] = []
    add = lambda id, target, *args, **kw: S.append(Spec(id, target, list(args), **kw))  # noqa: E731

    # ---- lieflow.lie: so(n)/SO(n) ----
    add("lie.hat_n", "lie.hat_n", A("c", np.array([0.4, 0.1, 0.2, -0.3, 0.2, 0.5]), "vec"))
    add("lie.vee_n", "lie.vee_n", A("xi", XI, "skew"))
    add("lie.so_exp", "lie.so_exp", A("xi", XI, "skew"))
    add("lie.so_log", "lie.so_log", A("R", R3, "rot"))
    add("lie.cayley", "lie.cayley", A("xi", XI, "skew"))
    add("lie.cayley_inv", "lie.cayley_inv", A("R", R3, "rot"))
    for f in ("dexp", "dexp_inv", "ad"):
        add(f"lie.{f}", f"lie.{f}", A("xi", XI, "skew"), A("eta", ETA, "skew"))
    add("lie.ad_star", "lie.ad_star", A("xi", XI, "skew"), A("mu", ETA, "skew"))
    add("lie.Ad", "lie.Ad", A("g", R3, "rot"), A("xi", XI, "skew"))
    add("lie.is_rotation", "lie.is_rotation", A("R", R3, "mat"),
        A("tol", 1e-10, "float", kw=True, positive=True))
    add("lie.project_to_so", "lie.project_to_so", A("M", X3, "mat"))
    add("lie.product_Ad", "lie.product_Ad", A("g", R3, "rot"), A("h", R3B, "rot"),
        A("xi", XI, "skew"), A("eta", ETA, "skew"))
    add("lie.product_bracket", "lie.product_bracket", A("xi1", XI, "skew"), A("eta1", ETA, "skew"),
        A("xi2", ETA, "skew"), A("eta2", XI, "skew"))
    # SO(3) / SE(3) fast path
    add("lie.hat", "lie.hat", A("w", W3, "vec"))
    add("lie.vee", "lie.vee", A("xi", rodrigues(W3) - rodrigues(W3).T, "skew"))
    for f in ("so3_exp", "so3_cayley"):
        add(f"lie.{f}", f"lie.{f}", A("w", W3, "vec"))
    add("lie.so3_log", "lie.so3_log", A("R", R3, "rot"), A("strict", False, "bool", kw=True))
    add("lie.so3_cayley_inv", "lie.so3_cayley_inv", A("R", R3, "rot"))
    for f in ("so3_jacobian_right", "so3_jacobian_left"):
        add(f"lie.{f}", f"lie.{f}", A("w", W3, "vec"), A("inverse", True, "bool", kw=True))
    add("lie.se3_exp", "lie.se3_exp", A("xi", SE3XI, "vec"))
    add("lie.se3_log", "lie.se3_log", A("g", G4, "se3"), A("strict", False, "bool", kw=True))
    add("lie.se3_Ad", "lie.se3_Ad", A("g", G4, "se3"))
    add("lie.se3_inverse", "lie.se3_inverse", A("g", G4, "se3"))
    add("lie.se3_compose", "lie.se3_compose", A("g", G4, "se3"), A("h", H4, "se3"))
    # the uniform group verbs (issue 30): so_*, so3_*, se3_* beside the aliases above
    add("lie.so_hat", "lie.so_hat", A("c", np.array([0.4, 0.1, 0.2, -0.3, 0.2, 0.5]), "vec"))
    add("lie.so_vee", "lie.so_vee", A("xi", XI, "skew"))
    add("lie.so_compose", "lie.so_compose", A("g", R3, "rot"), A("h", R3B, "rot"))
    add("lie.so_inverse", "lie.so_inverse", A("R", R3, "rot"))
    add("lie.so_act", "lie.so_act", A("R", R3, "rot"), A("x", W3, "vec"))
    add("lie.so_cayley", "lie.so_cayley", A("xi", XI, "skew"))
    add("lie.so_cayley_inv", "lie.so_cayley_inv", A("R", R3, "rot"))
    for f in ("so_dexp", "so_dexp_inv", "so_ad"):
        add(f"lie.{f}", f"lie.{f}", A("xi", XI, "skew"), A("eta", ETA, "skew"))
    add("lie.so_ad_star", "lie.so_ad_star", A("xi", XI, "skew"), A("mu", ETA, "skew"))
    add("lie.so_Ad", "lie.so_Ad", A("g", R3, "rot"), A("xi", XI, "skew"))
    for f in ("so_jacobian_right", "so_jacobian_left"):
        add(f"lie.{f}", f"lie.{f}", A("xi", XI, "skew"), A("inverse", True, "bool", kw=True))
    add("lie.so3_hat", "lie.so3_hat", A("w", W3, "vec"))
    add("lie.so3_vee", "lie.so3_vee", A("xi", rodrigues(W3) - rodrigues(W3).T, "skew"))
    add("lie.so3_compose", "lie.so3_compose", A("R1", R3, "rot"), A("R2", R3B, "rot"))
    add("lie.so3_inverse", "lie.so3_inverse", A("R", R3, "rot"))
    add("lie.so3_act", "lie.so3_act", A("R", R3, "rot"), A("x", W3, "vec"))
    add("lie.so3_Ad", "lie.so3_Ad", A("R", R3, "rot"), A("w", W3, "vec"))
    add("lie.so3_ad", "lie.so3_ad", A("u", W3, "vec"), A("v", -W3, "vec"))
    add("lie.so3_ad_star", "lie.so3_ad_star", A("xi", W3, "vec"), A("mu", 2 * W3, "vec"))
    add("lie.se3_hat", "lie.se3_hat", A("xi", SE3XI, "vec"))
    SE3X = np.block([[rodrigues(W3) - rodrigues(W3).T, SE3XI[3:, None]], [np.zeros((1, 4))]])
    add("lie.se3_vee", "lie.se3_vee", A("X", SE3X, "mat"))
    add("lie.se3_Ad[xi]", "lie.se3_Ad", A("g", G4, "se3"), A("xi", SE3XI, "vec"))
    add("lie.se3_act", "lie.se3_act", A("g", G4, "se3"), A("x", W3, "vec"))
    add("lie.se3_ad", "lie.se3_ad", A("xi", SE3XI, "vec"), A("eta", -SE3XI, "vec"))
    add("lie.se3_ad_star", "lie.se3_ad_star", A("xi", SE3XI, "vec"), A("mu", 2 * SE3XI, "vec"))
    for f in ("se3_jacobian_right", "se3_jacobian_left"):
        add(f"lie.{f}", f"lie.{f}", A("xi", SE3XI, "vec"), A("inverse", True, "bool", kw=True))
    # GL+(n)
    add("lie.svd_coordinates", "lie.svd_coordinates", A("X", X3, "gl"))
    add("lie.from_svd", "lie.from_svd", A("R", R3, "rot"), A("a", A3, "vec"), A("S", R3B, "rot"))
    add("lie.polar", "lie.polar", A("X", X3, "gl"))
    add("lie.stratum", "lie.stratum", A("X", X3, "gl"), A("tol", 1e-8, "float", kw=True))
    # rotation interop (issue 15): quaternions, Euler angles, scipy Rotation objects
    add("lie.to_quaternion", "lie.to_quaternion", A("R", R3, "rot"),
        A("scalar_first", True, "bool", kw=True))
    add("lie.from_quaternion", "lie.from_quaternion", A("q", np.array([0.9, 0.1, -0.3, 0.2]), "vec"),
        A("scalar_first", False, "bool", kw=True))
    add("lie.to_euler", "lie.to_euler", A("R", R3, "rot"), A("seq", "ZXZ", "str"))
    add("lie.from_euler", "lie.from_euler", A("angles", np.array([0.3, -1.2, 2.5]), "vec"),
        A("seq", "xyz", "str"))
    add("lie.to_scipy", "lie.to_scipy", A("R", R3, "rot"))
    add("lie.from_scipy", "lie.from_scipy", A("rotation", Lazy(_scipy_rotation), "obj"))

    # ---- lieflow.pseudo_rigid ----
    P = "pseudo_rigid."
    for f in ("left_inertia", "right_inertia"):
        add(P + f, P + f, A("X", X3, "gl"), A("xi", XI, "skew"))
    for f in ("bi_inertia", "bi_inertia_eigen"):
        add(P + f, P + f, A("X", X3, "gl"))
    add(P + "locked_inertia", P + "locked_inertia", A("X", X3, "gl"), A("action", "two-sided", "str"))
    for f in ("bi_inertia_apply", "bi_inertia_quadratic_form", "vertical_vector"):
        add(P + f, P + f, A("X", X3, "gl"), A("xi", XI, "skew"), A("eta", ETA, "skew"))
    add(P + "bi_inertia_solve", P + "bi_inertia_solve", A("X", X3, "gl"), A("lam", XI, "skew"),
        A("gam", ETA, "skew"))
    for f in ("left_connection", "right_connection", "bi_connection", "angular_momentum",
              "circulation", "to_body", "kinetic_energy", "riemann_variables"):
        add(P + f, P + f, A("X", X3, "gl"), A("V" if f in ("angular_momentum", "circulation",
                                                         "to_body", "kinetic_energy",
                                                         "riemann_variables") else "Y", V3, "mat"))
    add(P + "horizontal_part", P + "horizontal_part", A("X", X3, "gl"), A("Y", V3, "mat"),
        A("action", "left", "str"))
    add(P + "from_body", P + "from_body", A("R", R3, "rot"), A("a", A3, "vec"), A("S", R3B, "rot"),
        A("Omega", XI, "skew"), A("adot", np.array([0.1, -0.2, 0.05]), "vec"),
        A("Lambda", ETA, "skew"))
    add(P + "stratum", P + "stratum", A("X", X3, "gl"), A("tol", 1e-8, "float", kw=True))
    Q = X3 @ X3.T
    add(P + "riemann_bracket", P + "riemann_bracket", A("Q", Q, "mat"), A("N", X3 @ V3.T, "mat"),
        A("dfdQ", skew3(1, 0, 0) + np.eye(3), "mat"), A("dfdN", V3, "mat"),
        A("dgdQ", np.eye(3), "mat"), A("dgdN", XI, "mat"))
    add(P + "reduce", P + "reduce", A("X", X3, "gl"), A("P", V3, "mat"))
    add(P + "reconstruct", P + "reconstruct", A("R", R3, "rot"), A("S", R3B, "rot"), A("a", A3, "vec"),
        A("p_a", np.array([0.1, -0.2, 0.05]), "vec"), A("p_Omega", XI, "skew"),
        A("p_Lambda", ETA, "skew"))
    add(P + "adjoint_motion", P + "adjoint_motion", A("X", X3, "gl"), A("P", V3, "mat"))
    LOOP = np.array([[1.0, 0.0, 0.2], [0.0, 1.0, -0.1], [-1.0, 0.0, 0.3], [0.0, -1.0, 0.0]])
    add(P + "loop_circulation", P + "loop_circulation", A("X", X3, "gl"), A("V", V3, "mat"),
        A("labels", LOOP, "mat"))
    add(P + "loop_area", P + "loop_area", A("labels", LOOP, "mat"))
    add(P + "guichardet_connection", P + "guichardet_connection",
        A("masses", np.array([1.0, 2.0, 0.5, 1.5]), "vec"), A("positions", LOOP, "mat"),
        A("velocities", LOOP @ V3.T, "mat"))
    add(P + "particle_locked_inertia", P + "particle_locked_inertia",
        A("masses", np.array([1.0, 2.0, 0.5, 1.5]), "vec"), A("positions", LOOP, "mat"))
    add(P + "reduced_euler_lagrange", P + "reduced_euler_lagrange",
        A("lagrangian", riemann_lagrangian, "fn"), A("Q", X3 @ X3.T, "mat"),
        A("N", X3 @ V3.T, "mat"), A("gradient", None, "obj", opt=True))
    add(P + "RightReduced", P + "RightReduced", A("n", 3, "int", positive=True),
        A("potential", Lazy(_svk), "obj", opt=True), A("reconstruct", True, "bool", kw=True))
    svk = Lazy(_svk)
    # the equations of motion (001 (3.20), (4.8), Prop. 4.2, (7.24)-(7.28)); issue 25
    add(P + "riemann_vector_field", P + "riemann_vector_field", A("Q", Q, "mat"),
        A("N", X3 @ V3.T, "mat"), A("potential", svk, "obj", opt=True))
    add(P + "e_term", P + "e_term", A("a", A3, "vec"), A("Omega", XI, "skew"),
        A("Lambda", ETA, "skew"))
    a4 = np.array([1.4, 1.1, 0.9, 0.6])      # n = 4: the general path (n = 3 is the fast path)
    add(P + "e_term[n=4]", P + "e_term", A("a", a4, "vec"), A("Omega", SKEW4, "skew"),
        A("Lambda", -0.5 * SKEW4.T @ SKEW4 @ SKEW4, "skew"))
    add(P + "lagrange_vector_field", P + "lagrange_vector_field", A("a", A3, "vec"),
        A("Omega", XI, "skew"), A("Lambda", ETA, "skew"), A("potential", svk, "obj", opt=True))
    add(P + "lagrange_vector_field[n=4,callable]", P + "lagrange_vector_field", A("a", a4, "vec"),
        A("Omega", SKEW4, "skew"), A("Lambda", np.zeros((4, 4)), "skew"),
        A("potential", Lazy(lambda lf: lf.potentials.Callable(u_value, u_gradient)), "obj",
          opt=True))
    for f in ("reduced_hamiltonian", "reduced_vector_field"):
        add(P + f, P + f, A("a", A3, "vec"), A("p_a", np.array([0.1, -0.2, 0.05]), "vec"),
            A("p_Omega", XI, "skew"), A("p_Lambda", ETA, "skew"),
            A("potential", svk, "obj", opt=True))
    for f in ("amended_potential", "amended_hessian"):
        add(P + f, P + f, A("X", X3, "gl"), A("lam", XI, "skew"), A("gam", ETA, "skew"),
            A("potential", svk, "obj"))
    for f in ("augmented_potential", "augmented_gradient", "augmented_hessian"):
        add(P + f, P + f, A("X", X3, "gl"), A("xi", XI, "skew"), A("eta", ETA, "skew"),
            A("potential", svk, "obj"))
    add(P + "augmented_hessian[V]", P + "augmented_hessian", A("X", X3, "gl"), A("xi", XI, "skew"),
        A("eta", ETA, "skew"), A("potential", svk, "obj"), A("V", V3, "mat", kw=True, opt=True))
    add(P + "equilibrium_directions", P + "equilibrium_directions", A("a", A3, "vec"))
    add(P + "index_symbols", P + "index_symbols", A("a", A3, "vec"))
    add(P + "relative_equilibria", P + "relative_equilibria", A("potential", svk, "obj"),
        A("velocities", (0.5 * skew3(1, 0, 0), 0.9 * skew3(1, 0, 0)), "obj", kw=True, opt=True),
        A("bounds", (0.05, 3.0), "vec", kw=True), A("starts", 2, "int", kw=True, positive=True),
        slow=True)
    add(P + "relative_equilibria[shape]", P + "relative_equilibria", A("potential", Lazy(
        lambda lf: lf.potentials.Stretch(1.0)), "obj"), A("shape", np.array([1.5, 1.2, 1.0]), "vec",
        kw=True, opt=True), A("plane", (0, 1), "obj", kw=True, opt=True),
        A("incompressible", False, "bool", kw=True), slow=True)
    add("RelativeEquilibrium.motion", "@releq.motion", A("t", np.array([0.0, 0.5]), "bcast"))
    add("RelativeEquilibrium.stability", "@releq.stability")

    # ---- lieflow.ellipsoids, lieflow.continuation ----
    E = "ellipsoids."
    add(E + "maclaurin", E + "maclaurin", A("e", 0.5, "float"),
        A("G", 1.0, "float", kw=True, positive=True), A("rho", 1.0, "float", kw=True, positive=True))
    for f in ("jacobi", "dedekind"):
        add(E + f, E + f, A("a2_over_a1", 0.6, "float", positive=True))
    add(E + "riemann_s", E + "riemann_s", A("a2_over_a1", 0.6, "float", positive=True),
        A("f", -1.0, "float"))
    add(E + "maclaurin_jacobi_bifurcation", E + "maclaurin_jacobi_bifurcation",
        A("G", 1.0, "float", kw=True, positive=True), A("rho", 1.0, "float", kw=True, positive=True))
    add(E + "index_symbols", E + "index_symbols", A("a", A3, "vec"))
    add("continuation.follow", "continuation.follow",
        A("start", Lazy(lambda lf: lf.ellipsoids.maclaurin(0.3)), "obj"), A("parameter", "e", "str"),
        A("stop", 0.32, "float"), A("stability", False, "bool", kw=True),
        A("step", 1e-2, "float", kw=True, positive=True),
        A("max_points", 50, "int", kw=True, positive=True), slow=True)
    add("Branch.values_of", "@branch.values_of", A("name", "Omega2_over_piGrho", "str"))
    add("Branch.switch", "@branch.switch", A("point", Lazy(_branch_point), "obj"),
        A("stop", 0.82, "float", kw=True, opt=True),
        A("direction", 1.0, "float", kw=True, opt=True),
        slow=True)
    add("Branch.plot", "@branch.plot", A("y", "L", "str", kw=True), slow=True)

    # ---- lieflow.potentials ----
    add("potentials.Harmonic", "potentials.Harmonic", A("k", 1.3, "float"))
    add("potentials.SaintVenantKirchhoff", "potentials.SaintVenantKirchhoff", A("lam", 1.0, "float"),
        A("mu", 2.0, "float"))
    add("potentials.Volumetric", "potentials.Volumetric", A("kappa", 0.5, "float"),
        A("gamma", 1.4, "float"))
    add("potentials.Stretch", "potentials.Stretch", A("k", 1.1, "float"))
    add("potentials.SelfGravity", "potentials.SelfGravity", A("G", 1.0, "float", positive=True),
        A("rho", 1.0, "float", positive=True))
    add("potentials.Zero", "potentials.Zero")
    # Callable is fuzzed through its use (value, gradient, hessian call the Python functions).
    add("potentials.Callable", "use:potentials.Callable", A("value", u_value, "fn"),
        A("gradient", u_gradient, "fn"), A("hessian", u_hessian, "fn", opt=True))
    for p in ("harmonic", "svk", "volumetric", "stretch", "selfgrav", "zero", "sum", "callable"):
        add(f"Potential[{p}].value", f"@{p}.value", A("X", X3, "gl"))
        add(f"Potential[{p}].gradient", f"@{p}.gradient", A("X", X3, "gl"))
        add(f"Potential[{p}].hessian", f"@{p}.hessian", A("X", X3, "gl"), A("V", V3, "mat"))
        add(f"Potential[{p}].__add__", f"@{p}.__add__", A("other", Lazy(
            lambda lf: lf.potentials.Harmonic(0.5)), "obj"))

    # ---- lieflow.surfaces ----
    add("surfaces.Plane", "surfaces.Plane")
    add("surfaces.HyperbolicPlane", "surfaces.HyperbolicPlane")
    add("surfaces.Sphere", "surfaces.Sphere", A("radius", 1.0, "float", positive=True))
    add("surfaces.Torus", "surfaces.Torus", A("a", 2.0, "float", positive=True),
        A("b", 0.7, "float", positive=True))
    add("surfaces.Quadric", "surfaces.Quadric", A("a", 0.8, "float"), A("b", -0.5, "float"))
    add("surfaces.Revolution", "use:surfaces.Revolution", A("r", torus_r, "fn"),
        A("z", torus_z, "fn"), A("s_range", (-math.pi, math.pi), "vec"))
    add("surfaces.Graph", "use:surfaces.Graph", A("f", saddle, "fn"))
    add("surfaces.MetricSurface", "use:surfaces.MetricSurface", A("metric", sphere_metric, "fn"),
        A("frame", sphere_frame, "fn"), A("domain", inside, "fn", opt=True))
    for s, x in SURFACE_POINT.items():
        for f in ("curvature", "metric", "frame", "connection"):
            add(f"Surface[{s}].{f}", f"@{s}.{f}", A("x", np.array(x), "vec"))
    add("Surface[metric].check_frame", "@metric.check_frame", A("x", np.array([1.2, 0.4]), "vec"),
        A("tol", 1e-10, "float", kw=True))

    # ---- lieflow.elliptic ----
    add("elliptic.ellipj", "elliptic.ellipj", A("u", np.array([0.3, 1.2]), "bcast"),
        A("m", 0.5, "bcast"))
    add("elliptic.ellipk", "elliptic.ellipk", A("m", np.array([0.25, 0.7]), "bcast"))
    add("elliptic.ellipf", "elliptic.ellipf", A("phi", np.array([0.3, 1.2]), "bcast"),
        A("m", 0.5, "bcast"))

    # ---- system constructors ----
    add("RigidBody", "RigidBody", A("inertia", np.array([1.0, 2.0, 3.0]), "vec"))
    add("GeneralizedRigidBody", "GeneralizedRigidBody", A("J", np.array([1.0, 2.0, 3.0, 4.0]), "vec"))
    add("HeavyTop", "HeavyTop", A("inertia", np.array([1.0, 2.0, 3.0]), "vec"), A("mgl", 0.7, "float"),
        A("chi", np.array([0.2, -0.3, 1.0]), "vec", kw=True))
    for c in ("SphericalPendulum", "Pendulum", "SphereParticle"):
        add(c, c, A("mass", 2.0, "float", positive=True), A("length", 1.5, "float", positive=True),
            A("g", 9.81, "float"))
    add("FrameTop", "FrameTop", A("space", Lazy(lambda lf: lf.spaces.Sphere(3, radius=1.5)), "obj"),
        A("mass", 1.3, "float", positive=True), A("inertia", A3, "vec"))
    add("spaces.Euclidean", "spaces.Euclidean", A("n", 3, "int", opt=True))
    for f in ("Sphere", "Hyperbolic"):
        add("spaces." + f, "spaces." + f, A("n", 3, "int", opt=True),
            A("radius", 1.5, "float", opt=True, positive=True))
    add("spaces.Riemannian", "use:spaces.Riemannian", A("metric", conformal_metric, "fn"),
        A("frame", conformal_frame, "fn"), A("domain", ball, "fn", opt=True))
    add("RollingDisk", "RollingDisk", A("mass", 1.0, "float", positive=True),
        A("radius", 0.5, "float", positive=True), A("roll_inertia", 0.125, "float", positive=True),
        A("turn_inertia", 0.0625, "float", positive=True), A("spring", 0.4, "float", kw=True),
        A("tilt", 0.1, "float", kw=True))
    add("PseudoRigidBody", "PseudoRigidBody", A("n", 3, "int", positive=True),
        A("potential", svk, "obj", opt=True), A("check_det", True, "bool", kw=True))
    add("PseudoRigidBody[incompressible]", "PseudoRigidBody", A("n", 3, "int", positive=True),
        A("potential", svk, "obj", opt=True), A("incompressible", True, "bool", kw=True))
    add("RelativisticTangentTop", "RelativisticTangentTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 0.2, "float", positive=True),
        A("surface", Lazy(lambda lf: lf.surfaces.Sphere(1.0)), "obj", opt=True))
    add("RelativisticTangentTop[tensor]", "RelativisticTangentTop",
        A("mass", 1.0, "float", positive=True),
        A("inertia", np.array([[0.2, 0.05], [0.05, 0.08]]), "mat"),
        A("surface", Lazy(lambda lf: lf.surfaces.Sphere(1.0)), "obj", opt=True))
    add("WeakFieldTop", "WeakFieldTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 1e-3, "float", positive=True), A("gm", 1e-4, "float", kw=True, opt=True))
    add("WeakFieldTop[g]", "WeakFieldTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 1e-3, "float", positive=True), A("g", (0.0, -0.1), "vec", kw=True, opt=True))
    add("StaticFieldTop", "StaticFieldTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 0.2, "float", positive=True), A("gm", 0.15, "float", kw=True, opt=True))
    add("StaticFieldTop[g]", "StaticFieldTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 0.2, "float", positive=True), A("g", (0.0, -0.1), "vec", kw=True, opt=True))
    add("StaticFieldTop[surface]", "StaticFieldTop", A("mass", 1.0, "float", positive=True),
        A("inertia", 0.2, "float", positive=True), A("g", (0.2, 0.0), "vec", kw=True, opt=True),
        A("surface", Lazy(lambda lf: lf.surfaces.Sphere(1.0)), "obj", kw=True, opt=True))
    add("TangentTop", "TangentTop", A("surface", Lazy(lambda lf: lf.surfaces.Sphere(1.0)), "obj"),
        A("mass", 1.0, "float", positive=True), A("inertia", 0.5, "float", positive=True),
        A("embedded", True, "bool", kw=True))
    add("ChargedParticle", "ChargedParticle", A("top", lazy_recv("tt"), "obj"),
        A("charge", 0.7, "float"))
    add("RollingDisks", "RollingDisks", A("r1", 1.0, "float", positive=True),
        A("r2", 0.7, "float", positive=True), A("gamma1", 0.3 + 0.1j, "vec", complex_ok=True),
        A("gamma2", np.array([-0.2, 0.25]), "vec", complex_ok=True),
        A("m1", 1.0, "float", positive=True), A("m2", 1.5, "float", positive=True),
        A("inertia1", 0.8, "float", positive=True), A("inertia2", 0.6, "float", positive=True),
        A("rolling_constant", 0.3, "float", kw=True))
    add("RollingSpheres", "RollingSpheres", A("r1", 0.7, "float", positive=True),
        A("r2", 1.3, "float", positive=True), A("gamma1", np.array([0.1, -0.2, 0.15]), "vec"),
        A("gamma2", np.array([-0.3, 0.2, 0.4]), "vec"), A("m1", 2.0, "float", positive=True),
        A("m2", 3.5, "float", positive=True), A("inertia1", I_SPH1, "mat"),
        A("inertia2", I_SPH2, "mat"))

    # ---- methods of every system (the System protocol and each class's own) ----
    for key in SYSTEMS:
        st = state_of(key)
        for f in ("energy", "invariants", "casimirs"):
            add(f"{key}.{f}", f"@{key}.{f}", A("states", st, "vec"))
        add(f"{key}.methods", f"@{key}.methods")
    own = {
        "rb": [("angular_velocity", [A("states", M3, "vec")]),
               ("sensitivity_methods", []),
               ("spatial_momentum", [A("states", M3, "vec"), A("attitude", R3, "rot")]),
               ("exact_solution", [A("M0", M3, "vec"), A("t", np.array([0.0, 0.7, 2.0]), "bcast")]),
               ("exact_solution[attitude]", [A("M0", M3, "vec"), A("t", np.array([0.0, 0.7, 2.0]), "bcast"),
                                             A("attitude", R3, "rot", kw=True, opt=True)])],
        "grb": [("state", [A("M", np.array([[0, .3, -.2, .5], [-.3, 0, .1, .4], [.2, -.1, 0, -.6],
                                            [-.5, -.4, .6, 0]]), "skew")]),
                ("matrix", [A("states", np.array([0.3, -0.2, 0.5, 0.1, 0.4, -0.6]), "vec")])],
        "ht": [("state", [A("M", M3, "vec"), A("Gamma", np.array([0.0, 0.6, 0.8]), "vec", opt=True)]),
               ("state[attitude]", [A("M", M3, "vec"), A("attitude", R3, "rot", kw=True, opt=True)]),
               ("spatial_momentum", [A("states", np.array([1.0, .5, -.3, 0, .6, .8]), "vec"),
                                     A("attitude", R3, "rot")])],
        "sp": [("state_from_spherical", [A("theta", 0.8, "bcast"), A("phi", 0.1, "bcast"),
                                         A("thetadot", 0.3, "bcast", opt=True),
                                         A("phidot", 1.2, "bcast", opt=True)]),
               ("vertical_momentum", [A("states", state_of("sp"), "vec")])],
        "pend": [("exact_solution", [A("amplitude", 0.8, "bcast"),
                                     A("t", np.array([0.0, 0.5]), "bcast")])],
        "spart": [("from_spherical", [A("states", Lazy(lambda lf: lf.SphericalPendulum(
            2.0, 1.5, 9.81).state_from_spherical(0.8, 0.1, 0.3, 1.2)), "vec")])],
        "disk": [("state", [A("q", np.array([0.1, -0.2, 0.3, 0.7]), "vec"),
                            A("thetadot", 2.0, "float"), A("phidot", 0.5, "float")]),
                 ("constraint_residual", [A("states", state_of("disk"), "vec")])],
        "prb": [(f, [A("states", state_of("prb"), "vec")])
                for f in ("angular_momentum", "circulation", "singular_values")]
        + [("project_momentum", [A("X", X3, "gl"), A("P", V3, "mat")])],
        "rrb": [(f, [A("states", state_of("rrb"), "vec")])
                for f in ("angular_momentum", "circulation", "hamiltonian_parts", "reconstruct")]
        + [("reduce", [A("X", X3, "gl"), A("P", V3, "mat")])],
        "ft": [(f, [A("states", state_of("ft"), "vec")])
               for f in ("position", "frame", "velocity", "angular_velocity", "killing_momenta",
                         "group_momentum", "translational_energy", "rotational_energy")]
        + [("group_inertia", []),
           ("state", [A("x", FT_X, "vec"), A("R", R3, "rot"), A("xdot", FT_V, "vec"),
                      A("omega", W3, "vec")])],
        "s3": [("reference_frame", [A("x", FT_X, "vec")])],
        "chart": [("reference_frame", [A("x", FT_X[:3], "vec")]),
                  ("check_frame", [A("x", FT_X[:3], "vec"), A("tol", 1e-10, "float", kw=True)])],
        "ftc": [(f, [A("states", state_of("ftc"), "vec")])
                for f in ("position", "frame", "velocity", "angular_velocity",
                          "translational_energy", "rotational_energy")]
        + [("state", [A("x", FT_X[:3], "vec"), A("R", R3, "rot"), A("xdot", FT_V[:3], "vec"),
                      A("omega", W3, "vec")])],
        "iprb": [(f, [A("states", state_of("iprb"), "vec")])
                 for f in ("angular_momentum", "circulation", "singular_values")]
        + [("project_momentum", [A("X", X3, "gl"), A("P", V3, "mat")])],
        "rtt": [("state", [A("x", np.array([1.2, 0.3]), "vec"), A("theta", 0.5, "float"),
                           A("xdot", np.array([0.3, 0.4]), "vec"), A("thetadot", 2.0, "float")]),
                ("momentum_94", [A("v", np.array([0.1, 0.5, 0.9]), "bcast"),
                                 A("p_theta", 0.7, "bcast")]),
                ("spin_rate_95", [A("v", np.array([0.1, 0.5, 0.9]), "bcast"),
                                  A("p_theta", 0.7, "bcast")]),
                ("energy_96", [A("v", 0.5, "bcast"), A("thetadot", np.array([0.0, 2.0]), "bcast")]),
                ("lagrangian", [A("x", np.array([1.2, 0.3]), "vec"), A("theta", 0.5, "float"),
                                A("xdot", np.array([0.3, 0.4]), "vec"),
                                A("thetadot", 2.0, "float")]),
                ("prescribed_inertia", [A("theta", np.array([0.0, 0.7]), "bcast"),
                                        A("velocity", np.array([0.6, 0.1]), "vec")]),
                ("prescribed_spin_rate", [A("theta", np.array([0.0, 0.7]), "bcast"),
                                          A("energy", 0.8, "bcast"),
                                          A("velocity", np.array([0.6, 0.1]), "vec")]),
                ("prescribed_potential", [A("theta", 0.3, "bcast"),
                                          A("energy", np.array([0.0, 0.8]), "bcast"),
                                          A("velocity", np.array([0.6, 0.1]), "vec")])]
        + [(f, [A("states", state_of("rtt"), "vec")])
           for f in ("velocities", "speed_and_spin", "killing_momenta")],
        "wft": [("state", [A("x", np.array([1.0, 0.5]), "vec"), A("theta", 0.1, "float"),
                           A("xdot", np.array([0.1, 0.2]), "vec"), A("thetadot", 0.3, "float")]),
                ("lagrangian", [A("x", np.array([1.0, 0.5]), "vec"), A("theta", 0.1, "float"),
                                A("xdot", np.array([0.1, 0.2]), "vec"), A("thetadot", 0.3, "float")]),
                ("angular_momentum", [A("states", state_of("wft"), "vec")])],
        "sft": [("state", [A("x", np.array([1.0, 0.0]), "vec"), A("theta", 0.3, "float"),
                           A("xdot", np.array([0.05, 0.38]), "vec"), A("thetadot", 1.2, "float")]),
                ("lagrangian", [A("x", np.array([1.0, 0.0]), "vec"), A("theta", 0.3, "float"),
                                A("xdot", np.array([0.05, 0.38]), "vec"),
                                A("thetadot", 1.2, "float")])]
        + [(f, [A("states", state_of("sft"), "vec")])
           for f in ("velocities", "angular_momentum", "killing_momenta")],
        "tt": [("state", [A("x", np.array([1.0, 0.3]), "vec"), A("theta", 0.2, "float"),
                          A("xdot", np.array([0.1, 0.3]), "vec"), A("thetadot", 1.5, "float")]),
               ("metric", [A("x", np.array([1.0, 0.3]), "vec"), A("theta", 0.2, "float")]),
               ("lagrangian", [A("x", np.array([1.0, 0.3]), "vec"), A("theta", 0.2, "float"),
                               A("xdot", np.array([0.1, 0.3]), "vec"),
                               A("thetadot", 1.5, "float")]),
               ("magnetic_analogue", [A("p_theta", 0.7, "float")])]
        + [(f, [A("states", state_of("tt"), "vec")])
           for f in ("velocities", "p_theta", "killing_momenta", "ambient_frame")],
        "cp": [("metric", [A("x", np.array([1.0, 0.3]), "vec")]),
               ("potential", [A("x", np.array([1.0, 0.3]), "vec")]),
               ("state", [A("x", np.array([1.0, 0.3]), "vec"), A("xdot", np.array([0.1, 0.3]), "vec")])]
        + [(f, [A("states", state_of("cp"), "vec")]) for f in ("velocities", "killing_momenta")],
        "rds": [("state", [A("theta", np.array([0.3, -1.1]), "vec"),
                           A("thetadot", np.array([0.7, 0.2]), "vec")]),
                ("mass_matrix", [A("theta", np.array([0.3, -1.1]), "vec")]),
                ("locked_inertia", [A("theta", np.array([0.3, -1.1]), "vec")]),
                ("angular_momentum", [A("states", state_of("rds"), "vec")]),
                ("positions", [A("states", state_of("rds"), "vec")]),
                ("relative_equilibria", [A("rolling_constant", 0.2, "float", opt=True),
                                         A("theta1_range", (0.0, 3.0), "vec", kw=True)])],
        "rsph": [("state", [A("z1", R3, "rot"), A("z2", R3B, "rot"), A("u", U_SPH, "vec"),
                            A("Omega1", np.array([1.1, -0.6, 0.8]), "vec"),
                            A("Omega2", np.array([-0.4, 0.9, 0.5]), "vec")]),
                 ("planar_state", [A("theta", np.array([0.3, -0.4]), "vec"), A("phi", 0.2, "float"),
                                   A("thetadot", np.array([0.5, 0.7]), "vec")]),
                 ("to_planar", [A("state", Lazy(lambda lf: RECEIVERS["rsph"](lf).planar_state(
                     [0.3, -0.4], 0.2, [0.5, 0.7])), "vec"), A("tol", 1e-9, "float", kw=True)])]
        + [(f, [A("states", state_of("rsph"), "vec")])
           for f in ("accelerations", "angular_momentum", "body_momenta", "centres",
                     "centres_of_mass", "contact_point", "spatial_momenta", "udot",
                     "lagrangian")]
        + [("curvature", [A("states", state_of("rsph"), "vec"),
                          A("Omega", np.array([[1.1, -0.6, 0.8], [-0.4, 0.9, 0.5]]), "vec"),
                          A("Omega_tilde", np.array([[0.2, 0.7, -0.3], [0.5, -0.1, 0.6]]), "vec")]),
           ("curvature_by_brackets", [
               A("states", state_of("rsph"), "vec"),
               A("Omega", np.array([[1.1, -0.6, 0.8], [-0.4, 0.9, 0.5]]), "vec"),
               A("Omega_tilde", np.array([[0.2, 0.7, -0.3], [0.5, -0.1, 0.6]]), "vec"),
               A("s", 5e-3, "float", kw=True, positive=True)])],
        "rdeq": [("state", [A("omega", 1.0, "float")])],
        "run": [("advance", [A("steps", 5, "int")]), ("state", [])]
        # Output control (issue 15).
        + [("finish", [A("t", 0.123, "float")]), ("steps_to", [A("t", 0.5, "float")]),
           ("save_at", [A("t_eval", np.array([0.0, 0.013, 0.05]), "vec")]),
           ("set_events", [A("functions", [event_m2], "obj"), A("directions", [0.0], "vec"),
                           A("terminal", [1], "obj"), A("tol", 0.0, "float")]),
           ("events_found", []), ("take_partial", []), ("checked_state", [])],
        "traj": [("energy", []), ("invariants", []), ("casimirs", []),
                 ("concatenate", [A("trajectories", Lazy(_two_runs), "obj")]),
                 ("to_xarray", [A("observables", True, "bool", kw=True)]),
                 ("save", [A("path", Lazy(lambda lf: _scratch_path("save.nc")), "path")])],
        "straj": [("vjp", [A("cotangent", np.array([1.0, -0.5, 0.2]), "vec")])],
    }
    for key, methods in own.items():
        for name, args in methods:
            attr = name.split("[")[0]
            add(f"{key}.{name}", f"@{key}.{attr}", *args)

    # ---- results that live on: NetCDF (lf.load) and lieflow.plot (issue 13) ----
    add("load", "load", A("path", Lazy(_saved_run), "path"))
    add("plot.invariants", "plot.invariants", A("traj", Lazy(_turning_box), "obj"), slow=True)
    add("plot.states", "plot.states", A("traj", Lazy(_turning_box), "obj"),
        A("fields", ["M"], "obj", kw=True, opt=True), slow=True)
    add("plot.work_precision", "plot.work_precision",
        A("results", {"splitting": ([1e-4, 1e-6], [0.01, 0.1])}, "obj"), slow=True)
    add("plot.animate", "plot.animate", A("traj", Lazy(_turning_box), "obj"),
        A("every", 2, "int", kw=True, positive=True), slow=True)

    # ---- lf.integrate with each system ----
    for key in SYSTEMS:
        add(f"integrate[{key}]", "integrate", A("system", lazy_recv(key), "obj"),
            A("state0", state_of(key), "vec"), A("dt", 0.01, "float", kw=True),
            A("steps", 10, "int", kw=True), A("method", None, "str", kw=True, opt=True),
            slow=key in ("prb", "iprb", "rrb", "ft", "rtt", "tt", "cp", "rds", "rsph"))
    ht_att = Lazy(lambda lf: RECEIVERS["ht"](lf).state(M3, attitude=R3))
    for key, st in (("rb", state_of("rb")), ("ht", ht_att)):
        add(f"integrate[{key},attitude]", "integrate", A("system", lazy_recv(key), "obj"),
            A("state0", st, "vec"), A("dt", 0.01, "float", kw=True),
            A("steps", 10, "int", kw=True), A("attitude", R3, "rot", kw=True, opt=True))
    add("integrate[rb,options]", "integrate", A("system", lazy_recv("rb"), "obj"),
        A("state0", np.array([[1.0, 0.5, -0.3], [0.2, -0.4, 0.9]]), "vec"),
        A("dt", 0.01, "float", kw=True), A("steps", 20, "int", kw=True),
        A("method", "splitting4", "str", kw=True, opt=True), A("save_every", 5, "int", kw=True, positive=True),
        A("chunk_steps", 7, "int", kw=True, opt=True, positive=True),
        A("threads", 1, "int", kw=True, opt=True), A("progress", False, "bool", kw=True))
    # ---- lf.integrate: output control (issue 15): t0, t_eval, events, event_tol ----
    # `steps` is fuzzed as an int by the specs above, where 10**12 steps are refused by the
    # memory check of the states they would save; with t_eval or events nothing is saved per
    # step, so 10**12 steps are a legitimate run beyond the harness's time limit: here it only
    # gets the wrong-object values ("obj").
    add("integrate[rb,t_eval]", "integrate", A("system", lazy_recv("rb"), "obj"),
        A("state0", np.array([1.0, 0.5, -0.3]), "vec"), A("dt", 0.01, "float", kw=True),
        A("steps", 20, "obj", kw=True, opt=True), A("t0", 0.5, "float", kw=True),
        A("t_eval", np.array([0.5, 0.513, 0.6, 0.7]), "vec", kw=True, opt=True))
    add("integrate[rb,events]", "integrate", A("system", lazy_recv("rb"), "obj"),
        A("state0", np.array([1.0, 0.5, -0.3]), "vec"), A("dt", 0.01, "float", kw=True),
        A("steps", 200, "obj", kw=True), A("events", event_m2, "fn", kw=True, opt=True),
        A("event_tol", 0.0, "float", kw=True))
    # ---- lf.integrate(..., sensitivity=True) (issue 26) ----
    add("integrate[rb,sensitivity]", "integrate", A("system", lazy_recv("rb"), "obj"),
        A("state0", np.array([[1.0, 0.5, -0.3], [0.2, -0.4, 0.9]]), "vec"),
        A("dt", 0.01, "float", kw=True), A("steps", 20, "int", kw=True),
        A("save_every", 5, "int", kw=True, positive=True),
        A("sensitivity", True, "bool", kw=True))
    # ---- chaos (issue 27): lf.lyapunov, lf.poincare_section ----
    add("lyapunov[ht]", "lyapunov", A("system", lazy_recv("ht"), "obj"),
        A("state0", state_of("ht"), "vec"), A("dt", 0.01, "float", kw=True, positive=True),
        A("steps", 30, "int", kw=True, positive=True),
        A("method", None, "str", kw=True, opt=True),
        A("renormalise_every", 10, "int", kw=True, positive=True), module="integrate")
    add("poincare_section[ht]", "poincare_section", A("system", lazy_recv("ht"), "obj"),
        A("state0", state_of("ht"), "vec"), A("section", section_gamma1, "fn"),
        A("direction", 1.0, "float", kw=True), A("crossings", 2, "int", kw=True, positive=True),
        A("method", None, "str", kw=True, opt=True),
        A("dt", 0.02, "float", kw=True, positive=True),
        A("max_steps", 3000, "int", kw=True, positive=True), module="integrate")
    # ---- periodic orbits (issue 27) ----
    add("periodic_orbit[rb]", "periodic_orbit", A("system", lazy_recv("rb"), "obj"),
        A("state0", np.array([1.0, 0.3, 0.2]), "vec"), A("period", 10.86, "float", positive=True),
        A("method", "exact", "str", kw=True, opt=True),
        A("dt", 2.0, "float", kw=True, positive=True, opt=True),
        A("fix", "energy", "str", kw=True), A("relative", False, "bool", kw=True),
        A("tol", 1e-10, "float", kw=True, positive=True),
        A("max_iter", 30, "int", kw=True, positive=True), module="integrate")
    add("PeriodicOrbit.trajectory", "@porb.trajectory",
        A("steps", 8, "int", positive=True, opt=True),
        A("periods", 1, "int", kw=True, positive=True), module="integrate")
    add("RelativeEquilibrium.normal_modes", "@releq.normal_modes")
    add("continuation.periodic_family", "continuation.periodic_family",
        A("system", lazy_recv("rb"), "obj"), A("orbit", lazy_recv("porb"), "obj"),
        A("parameter", "energy", "str", kw=True),
        A("step", 0.02, "float", kw=True, positive=True),
        A("max_points", 3, "int", kw=True, positive=True), slow=True, module="integrate")
    add("PeriodicBranch.plot", "@pbranch.plot", A("x", "energy", "str", kw=True), slow=True,
        module="integrate")
    # ---- user-defined systems (issue 15) ----
    user_specs(add)
    forced_specs(add)
    ensemble_specs(add)
    return S


SPECS = build_specs()
