"""Where the demo scripts write: ``results/<script name>/`` under the repository root (gitignored),
whatever the working folder, beside the results of the demo scenes (whose ``output.folder`` is
``"../results/<name>"`` from ``demos/``). ``--out`` writes elsewhere (a relative path from the
working folder, as any command-line path)."""
import argparse
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]      # the repository
RESULTS = ROOT / "results"


def add_out(parser: argparse.ArgumentParser, script: str) -> None:
    """Give ``parser`` the option ``--out``, by default ``RESULTS / <stem of script>``."""
    parser.add_argument("--out", default=str(RESULTS / Path(script).stem),
                        help="output folder (default: %(default)s, whatever the working folder)")
