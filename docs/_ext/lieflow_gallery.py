"""Hooks of the documentation build (imported by docs/conf.py by name, so they pickle)."""


def reset_argv(gallery_conf, script_vars):
    """The command line of each example run by sphinx-gallery: ``--figure`` with no path.

    The examples draw their figures when given ``--figure`` and save them only when a path
    follows it, so the gallery (which captures open matplotlib figures itself) never writes
    into the tracked tree.
    """
    return ["--figure"]
