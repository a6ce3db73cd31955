"""Effective orders of the processed compositions (processed6/8/10, Processed::bcm6/8/10 in
crates/core/src/integrate/methods/composition.rs) in 40-digit arithmetic, away from the
round-off that limits the measurement in double precision (tests/integrators.rs).

The free rigid body I = (1, 2, 3), M0 = (1, 0.5, -0.3), split into its three axis rotations
(Strang S_h = R1(h/2) R2(h/2) R3(h) R2(h/2) R1(h/2)); the processed map is P^-1 K^N P with the
kernel K and the processor P read from composition.rs (the kernel's outer weights and the
tabulated processor halves g_1..g_k; P = (-g_0, ..., -g_k, g_0, ..., g_k), g_0 = -sum g_i). The
reference is Kahan-Li's order-8 composition with 600 steps. Prints the errors at T = 4 and the
observed orders; the kernels alone give 4, the processed maps 6, 8 and 10 (8 approached from
below: its leading error constant is small; below 1e-16 the 15 digits of the published
coefficients set a floor, which bends the last order of bcm10).

Needs mpmath (not a dependency of lieflow):  python scripts/processed_orders.py  (a few seconds).
"""

import pathlib
import re

import mpmath as mp

mp.mp.dps = 40
ROOT = pathlib.Path(__file__).resolve().parents[1]
SOURCE = (ROOT / "crates/core/src/integrate/methods/composition.rs").read_text()
I = [mp.mpf(1), mp.mpf(2), mp.mpf(3)]
M0 = [mp.mpf(1), mp.mpf("0.5"), mp.mpf("-0.3")]
T = mp.mpf(4)


def numbers(body):
    return [mp.mpf(x.replace("_", "")) for x in re.findall(r"-?\d+\.[\d_]+", body)]


def function(name):
    """The source text of `pub fn name()` of composition.rs."""
    start = SOURCE.index(f"pub fn {name}()")
    end = SOURCE.index("\n    }\n", start)
    return SOURCE[start:end]


def palindrome(outer):
    return outer + [1 - 2 * sum(outer)] + outer[::-1]


def bcm(name):
    """The kernel weights and the processor of `Processed::name()`."""
    body = function(name)
    named = {}
    for names, values in re.findall(r"let \(([^)]*)\) = \(([^)]*)\);", body):
        named.update(zip((n.strip() for n in names.split(",")), numbers(values)))
    for n, v in re.findall(r"let (a\d+) = (-?[\d._]+);", body):
        named[n] = numbers(v)[0]
    if "palindrome(&[" in body:
        outer_src = body.split("palindrome(&[")[1].split("]")[0]
    else:
        outer_src = body.split("let outer = [")[1].split("]")[0]
    outer = [named[t] if t in named else mp.mpf(t.replace("_", ""))
             for t in (x.strip() for x in outer_src.split(",")) if t]
    g = numbers(body.rsplit("&[", 1)[1].split("]")[0])
    half = [-sum(g)] + g
    return palindrome(outer), [-x for x in half] + half


def rotate(m, i, tau):
    a = -tau * m[i] / I[i]
    j, k = (i + 1) % 3, (i + 2) % 3
    c, s = mp.cos(a), mp.sin(a)
    m = list(m)
    m[j], m[k] = c * m[j] - s * m[k], s * m[j] + c * m[k]
    return m


def strang(m, t):
    for i, f in ((0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)):
        m = rotate(m, i, t * f)
    return m


def compose(m, weights, h):
    for w in weights:
        m = strang(m, w * h)
    return m


def run(kernel, processor, n):
    h = T / n
    m = compose(M0, processor, h)
    for _ in range(n):
        m = compose(m, kernel, h)
    return compose(m, [-x for x in reversed(processor)], h)


def main():
    kl8 = palindrome(numbers(function("kahan_li8")))
    ref = run(kl8, [], 600)
    steps = (6, 8, 12, 16, 24)
    for name in ("bcm6", "bcm8", "bcm10"):
        kernel, processor = bcm(name)
        for label, p in ((name, processor), (f"{name} kernel alone", [])):
            e = [mp.norm(mp.matrix(run(kernel, p, n)) - mp.matrix(ref)) for n in steps]
            orders = [mp.log(e[i] / e[i + 1]) / mp.log(mp.mpf(steps[i + 1]) / steps[i])
                      for i in range(len(steps) - 1)]
            print(f"{label:20s} errors " + " ".join(mp.nstr(x, 3) for x in e)
                  + "  orders " + " ".join(mp.nstr(o, 3) for o in orders))


if __name__ == "__main__":
    main()
