"""What the fuzz suite tolerates, each entry with its reason.

ALLOWED: failing-class results that are intended behaviour (matched by spec id, argument name and
bad-value name, shell-style patterns, and the outcome). They are counted as `allowed` in the
summary and never fail a test.

INFINITE_OK: result attributes that may legitimately be infinite (a value, not an overflow).

ISSUE_ITEMS: every failing-result group and the issue item it belongs to.

KNOWN_FAILING: the groups that still fail in the quick tier (open items of issue 16, or found by
this suite); their tests are xfail(strict=False). Remove a name when its fix lands: the test then
guards it.
"""

from fnmatch import fnmatchcase

# (spec id, argument, bad value, outcome, reason)
ALLOWED = [
    ("lie.is_rotation", "R", "*inf", "accepted-bad",
     "is_rotation is a predicate: a non-finite matrix is not a rotation (False), not an error"),
    ("lie.is_rotation", "R", "nan", "accepted-bad",
     "is_rotation is a predicate: a non-finite matrix is not a rotation (False), not an error"),
    ("RollingDisks", "gamma[12]", "complex*", "accepted-bad",
     "gamma1/gamma2 are points of the plane and may be given as complex numbers"),
    ("RollingDisks", "gamma[12]", "dropped-axis", "accepted-bad",
     "a real number is a point of the plane on the real axis (gamma as a complex number)"),
    ("GeneralizedRigidBody", "J", "wrong-last-axis", "accepted-bad",
     "J of another length n is the body of another so(n): valid"),
    ("mass_matrix", "positions", "wrong-last-axis", "accepted-bad",
     "positions of another dimension n are a body in R^n, whose mass matrix is (n, n): valid"),
    ("pseudo_rigid.particle_locked_inertia", "positions", "wrong-last-axis", "accepted-bad",
     "positions of another dimension n are particles in R^n, whose locked inertia is "
     "(n(n-1)/2, n(n-1)/2): valid"),
    ("pseudo_rigid.equilibrium_directions", "a", "wrong-last-axis", "accepted-bad",
     "semi-axes of another length n are another dimension: valid"),
    ("run.save_at", "t_eval", "wrong-last-axis", "accepted-bad",
     "t_eval is any number of output times: one more (still increasing, and a run has no end) "
     "is valid"),
    ("ellipsoids.riemann_s", "f", "*inf", "accepted-bad",
     "f = zeta/Omega = +-inf is the family of stationary figures (Dedekind's ellipsoids, EFE's "
     "f = inf), documented and computed on its own ray"),
    ("lie.hat_n", "c", "extra-axis", "accepted-bad",
     "vectorised over leading axes (numpy broadcasting): an extra axis is a batch"),
    ("HeavyTop", "chi", "None", "accepted-bad",
     "chi is optional: None selects the default"),
    ("integrate*", "state0", "broadcast-1e6", "timeout",
     "a batch of 10^6 initial states is a legitimate run that takes longer than the harness's "
     "time limit (it is refused only beyond the memory limits)"),
    ("ensemble.sweep", "params", "tuple-1", "accepted-bad",
     "(1.0,) is a valid sequence of one parameter value (the catalogue's 'obj' values assume a "
     "lieflow object)"),
    ("lie.to_scipy", "R", "*", "wrong-result",
     "the result is a scipy Rotation, which has no value equality (== is identity), so the harness "
     "cannot compare it with the valid call's; to_scipy is Rotation.from_quat(to_quaternion(R)) "
     "and to_quaternion is fuzzed with the same layouts under the 'same' contract"),
    ("pseudo_rigid.locked_inertia", "X", "n=60", "timeout",
     "the locked inertia at n = 60 is a dense n(n-1)/2-dimensional operator built in O(n^6): "
     "slow, not wrong (performance issue)"),
]

INFINITE_OK = {
    "angular_velocity_range": "RollingDisksEquilibrium: (lo, inf) when the angular velocity is "
                              "unbounded above",
    "f": "RelativeEquilibrium of lieflow.ellipsoids: f = zeta/Omega is +inf for a stationary "
         "figure (Dedekind's ellipsoids, EFE's f = inf)",
    "quantities": "RelativeEquilibrium of lieflow.ellipsoids: the dict holds f (above); its other "
                  "entries are attributes too, checked one by one",
}

# group -> the issue item it belongs to (the xfail reason)
ISSUE_ITEMS = {
    "panic": "issue 16 'Panic across the FFI' (stratum at large n)",
    "abort-alloc": "issue 16 'Process abort on allocation failure' (unchecked output allocations)",
    "silent-nan:integrate": "issue 16 'Silent NaN' - integrate at huge dt / |M|",
    "silent-nan:lie": "issue 16 'Silent NaN' - exponentials at |w| >= 1e16 (one rule for all)",
    "silent-nan:pseudo_rigid": "issue 16 'Silent NaN' - pseudo-rigid functions at small/large scales",
    "silent-nan:systems": "issue 16 'Silent NaN' - system observables at large scales (casimirs ...)",
    "accepted-nan": "issue 16 'Bad input accepted' - NaN in states/attitudes, callables returning NaN",
    "accepted-complex": "issue 16 'Bad input accepted' - complex/datetime64 arrays",
    "accepted-nonrotation": "issue 16 'Bad input accepted' - attitude that is not a rotation",
    "accepted-str-scalar": "issue 16 'Bad input accepted' - dt='0.01' and other numeric strings",
    "accepted-shape": "issue 16 'Bad input accepted' - shapes accepted by casting (bi_inertia(eye(1)) ...)",
    "accepted-conversion": "issue 16 'Bad input accepted' - objects/strings/None cast or ignored",
    "accepted-range": "issue 16 'Bad input accepted' - out-of-range sizes/parameters",
    "accepted-nonskew": "issue 16 'Bad input accepted' - non-skew matrix taken as so(n)",
    "wrong-type:ValueError": "issue 16 'Wrong exception types' - bare numpy ValueError (563 cases)",
    "wrong-type:TypeError-unnamed": "issue 16 'Wrong exception types' - TypeError not naming the argument",
    "wrong-type:OverflowError": "issue 16 'Wrong exception types' - OverflowError for huge ints",
    "wrong-type:integrate-system": "issue 16 'Wrong exception types' - lf.integrate('rb', ...)",
    "wrong-type:MemoryError": "issue 16 'Process abort on allocation failure' - numpy MemoryError "
                              "(materialising a broadcast view) instead of a typed size error",
    "wrong-type:other": "issue 16 'Wrong exception types' - other exception types",
    "rejected-valid": "found by this suite: WeakFieldTop(...).methods() raises TypeError "
                      "(_example_args passes gm positionally to a keyword-only argument)",
    "wrong-result": "found by this suite: a non-contiguous/list/read-only input gives another result",
    "mutated": "issue 16 'no input was ever mutated' (kept as a guard)",
    "harness": "an error of the fuzz suite itself",
}

KNOWN_FAILING: dict[str, str] = {}


def allowed(spec_id: str, arg: str, bad: str, outcome: str) -> bool:
    return any(fnmatchcase(spec_id, s) and fnmatchcase(arg, a) and fnmatchcase(bad, b) and outcome == o
               for s, a, b, o, _ in ALLOWED)
