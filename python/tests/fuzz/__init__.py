"""The fuzz suite of issue 16: every public callable x every argument x a catalogue of bad values,
each call in a worker subprocess, classified by one classifier.

  examples.py   the one table of valid example calls (+ receivers, valid states)
  catalogue.py  the one catalogue of bad values and their contracts; the numeric fuzz
  core.py       the case table, the classifier, the subprocess runner, the summary
  allowlist.py  intended exceptions (with reasons) and the groups still xfail
  test_fuzz.py  quick tier in `pytest python/tests`; LIEFLOW_FUZZ=full for the full tier
  test_hypothesis.py  hypothesis over the numeric arguments (in process)
  report.py / __main__.py  `python python/tests/fuzz --full --doc docs/fuzz.md`
"""
