"""`python3 -m lamina ARGS` runs lamina's command line, as the `lamina` executable does (same
subcommands, options, output and exit codes; docs/usage.md)."""

import sys

from lamina import _lamina


def main() -> int:
    return _lamina.cli(["python3 -m lamina"] + sys.argv[1:])


if __name__ == "__main__":
    sys.exit(main())
