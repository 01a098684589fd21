"""Command line: ``multiscale <command>``. User errors print one line each and exit 2."""
from __future__ import annotations

import argparse
import sys

from multiscale.errors import MultiscaleError, SceneError


def _info(args) -> int:
    import numpy
    import scipy

    import multiscale
    from multiscale.micro.fft import get_threads, pyfftw
    print(f"multiscale {multiscale.__version__}  numpy {numpy.__version__}  scipy {scipy.__version__}  "
          f"fft {'pyfftw' if pyfftw else 'scipy'} ({get_threads()} thread(s))")
    try:
        import dolfinx_solver  # noqa: F401  (must precede dolfinx in the PyPI wheel)
    except ImportError:
        pass
    try:
        import dolfinx
        print(f"dolfinx {dolfinx.__version__}")
    except ImportError:
        print("dolfinx not installed (macro models unavailable)")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="multiscale", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("info", help="versions and settings").set_defaults(func=_info)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except SceneError as exc:
        for line in exc.problems:
            print(f"error: {line}", file=sys.stderr)
        return 2
    except MultiscaleError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
