"""Command line: ``python -m rigidfem demo [--t-end S] [--output PNG]``."""

import argparse
import sys

from . import demo


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rigidfem", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="Kane's spin-up beam, nonlinear and linear models: a summary and a plot")
    d.add_argument("--t-end", type=float, default=30.0, help="simulated time in s (default 30)")
    d.add_argument("--output", default="rigidfem_demo.png", help="plot file (default rigidfem_demo.png)")
    args = parser.parse_args(argv)
    if args.command == "demo":
        demo.run(t_end=args.t_end, output=args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
