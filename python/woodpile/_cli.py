"""The ``woodpile`` command a wheel installs into the environment's ``bin``: it runs the binary
the wheel carries (``woodpile/bin/woodpile``), so ``woodpile run`` works in a fresh virtual
environment with no Rust toolchain. Installed from a clone without that binary, it runs the
next ``woodpile`` on the PATH (``make install``'s), or says how to get one."""

from __future__ import annotations

import os
import sys
from typing import List, NoReturn


def main(argv: List[str] = sys.argv) -> NoReturn:
    """Replaces this process with the real ``woodpile`` command, with ``argv``'s arguments."""
    from ._pipeline import find_woodpile

    try:
        binary = find_woodpile()
    except FileNotFoundError as e:
        sys.stderr.write(f"woodpile: {e}\n")
        sys.exit(127)
    os.execv(binary, [binary, *argv[1:]])


if __name__ == "__main__":
    main()
