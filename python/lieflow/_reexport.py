"""Helper that exposes a native submodule's public functions from a Python module."""


def reexport(native, namespace):
    """Copy every public attribute of ``native`` into ``namespace``; return their names."""
    names = sorted(n for n in dir(native) if not n.startswith("_"))
    for n in names:
        namespace[n] = getattr(native, n)
    return names
