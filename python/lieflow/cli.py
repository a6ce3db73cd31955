"""Command line: ``python -m lieflow demo``."""

import argparse

import numpy as np


def demo() -> None:
    """Print a short tour of lieflow computations."""
    import lieflow as lf

    print(f"lieflow {lf.__version__}")
    w = np.array([0.3, -0.2, 0.5])
    print("hat(w) =\n", lf.lie.hat(w))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="lieflow", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("demo", help="run the main demo")
    args = parser.parse_args(argv)
    if args.command == "demo":
        demo()
    return 0
