"""``python -m multiscale``: the ``multiscale`` command (``multiscale.cli.main``), for an environment
whose scripts folder is not on the PATH."""
import sys

from multiscale.cli import main

if __name__ == "__main__":
    sys.exit(main())
