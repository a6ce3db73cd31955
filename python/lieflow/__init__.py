"""lieflow: geometric mechanics on Lie groups with a Rust core.

Submodules
----------
lie           matrix Lie groups and algebras: SO(n), SO(3), SE(3), GL+(n), SO(n)×SO(n)
pseudo_rigid  generalized pseudo-rigid bodies on GL+(n) (inertia tensors, connections, momenta)
spaces        the 3-dimensional space forms of the FrameTop (Euclidean, Sphere, Hyperbolic)
elliptic      Jacobi elliptic functions sn, cn, dn and the integrals K(m), F(phi | m)
ellipsoids    self-gravitating fluid ellipsoids (Maclaurin, Jacobi, Dedekind, Riemann S-type)
continuation  continuation of families of relative equilibria, branch points, stability
io            trajectories as xarray Datasets and NetCDF files (Trajectory.save, load)
plot          plots and animations of trajectories (matplotlib)
ensemble      ensembles and parameter sweeps as Dask tasks (lazy xarray Datasets; needs dask)

Systems and integration
-----------------------
System                                                          base class of every system
RigidBody, GeneralizedRigidBody, HeavyTop, SphericalPendulum   Lie–Poisson systems of 000 §3–§5
PseudoRigidBody, potentials                                     pseudo-rigid bodies of 001
Pendulum, SphereParticle, RollingDisk                           canonical, constrained and
                                                                nonholonomic test problems
TangentTop, ChargedParticle, surfaces                           the tangent Euler top of 002 §II–III
RelativisticTangentTop, StaticFieldTop, WeakFieldTop            the relativistic top of 002 §IV
FrameTop, spaces                                                the top on R^3, S^3, H^3 (002 §V)
RollingSpheres                                                  two rolling spheres of 003 §2
RollingDisks                                                    two rolling disks of 003 §1
Canonical, Separable, LiePoisson                                user-defined systems from Python
                                                                callables (docs/user_systems.md)
Forced                                                          any system with a force or torque,
                                                                Rayleigh damping or double-bracket
                                                                dissipation (docs/forcing.md)
integrate(system, state0, dt=..., steps=..., method=...)        -> Trajectory
load(path)                                                      a Trajectory saved with
                                                                Trajectory.save (NetCDF)

Periodic orbits (docs/periodic_orbits.md)
-----------------------------------------
periodic_orbit(system, state0, period)                          -> PeriodicOrbit: shooting on the
                                                                method's map (monodromy, Floquet
                                                                multipliers; relative orbits)
periodic_orbit.from_mode(equilibrium, mode, amplitude)          the start of a Lyapunov family
continuation.periodic_family(system, orbit)                     -> PeriodicBranch

Chaos (docs/chaos.md)
---------------------
lyapunov(system, state0, dt=..., steps=...)                     -> LyapunovSpectrum: all the
                                                                Lyapunov exponents (repeated QR)
poincare_section(system, state0, section, dt=...)               -> (times, states) of crossings

Errors are subclasses of :class:`LieflowError` (itself a ``ValueError``); an argument of the
wrong type (complex, string or object arrays, ragged lists) is an :class:`ArgumentTypeError`
(a ``TypeError`` naming the argument).
"""

from ._lieflow import (
    ArgumentTypeError,
    ConvergenceError,
    DegenerateStratumError,
    InvalidArgumentError,
    LeftDomainError,
    LieflowError,
    LieflowWarning,
    NoUniqueLogError,
    NonFiniteError,
    NotInGroupError,
    ShapeError,
    UnsupportedMethodError,
    __version__,
)
from ._lieflow import (
    Canonical,
    ChargedParticle,
    EulerPoincare,
    Forced,
    FrameTop,
    GeneralizedRigidBody,
    HeavyTop,
    Integration,
    LiePoisson,
    Pendulum,
    PseudoRigidBody,
    RelativisticTangentTop,
    RigidBody,
    RollingDisk,
    RollingDisks,
    RollingDisksEquilibrium,
    RollingSpheres,
    Separable,
    SphereParticle,
    SphericalPendulum,
    StaticFieldTop,
    System,
    TangentTop,
    WeakFieldTop,
    inertia_tensor,
    mass_matrix,
    spatial_inertia,
)
from . import (continuation, ellipsoids, elliptic, io, lie, plot, potentials, pseudo_rigid, spaces,
               surfaces)
from . import ensemble  # imports dask and xarray only when its functions are called
from .integrate import Trajectory, integrate, load
from .chaos import LyapunovSpectrum, lyapunov, poincare_section
from .io import FileFormatError
from .periodic import PeriodicOrbit, periodic_orbit

#: The former name of the base class of the Lie–Poisson systems (kept for existing code).
LiePoissonSystem = System

__all__ = [
    "ArgumentTypeError",
    "Canonical",
    "ChargedParticle",
    "ConvergenceError",
    "DegenerateStratumError",
    "EulerPoincare",
    "FileFormatError",
    "LieflowWarning",
    "Forced",
    "FrameTop",
    "GeneralizedRigidBody",
    "HeavyTop",
    "Integration",
    "InvalidArgumentError",
    "LeftDomainError",
    "LiePoisson",
    "LiePoissonSystem",
    "LieflowError",
    "LyapunovSpectrum",
    "NoUniqueLogError",
    "NonFiniteError",
    "NotInGroupError",
    "Pendulum",
    "PeriodicOrbit",
    "PseudoRigidBody",
    "RelativisticTangentTop",
    "RigidBody",
    "RollingDisk",
    "RollingSpheres",
    "RollingDisks",
    "RollingDisksEquilibrium",
    "Separable",
    "SphereParticle",
    "ShapeError",
    "SphericalPendulum",
    "System",
    "TangentTop",
    "Trajectory",
    "UnsupportedMethodError",
    "StaticFieldTop",
    "WeakFieldTop",
    "__version__",
    "elliptic",
    "ensemble",
    "inertia_tensor",
    "integrate",
    "io",
    "lie",
    "load",
    "lyapunov",
    "mass_matrix",
    "periodic_orbit",
    "plot",
    "poincare_section",
    "potentials",
    "pseudo_rigid",
    "spaces",
    "spatial_inertia",
    "surfaces",
]
