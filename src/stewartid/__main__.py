"""``python -m stewartid COMMAND ...``, the same as the ``stewartid`` command."""

from stewartid.cli import main

if __name__ == "__main__":
    main()
