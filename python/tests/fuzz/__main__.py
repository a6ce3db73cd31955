"""Full tier of the fuzz suite: `python python/tests/fuzz --full [--run LABEL=PYTHON ...] [--doc docs/fuzz.md]`.

Runs the case table against each interpreter (default: this one, label "now"), prints the summary
and writes docs/fuzz.md (tables per label: calls per outcome class per module; failing groups with
one reproducer each). `--json DIR` keeps the raw results; `--from-json` re-renders from them.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from fuzz.report import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
