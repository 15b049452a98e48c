"""Command line: ``python -m rigidfem demo [--t-end S] [--output PNG]`` and
``python -m rigidfem bench [--output DIR] [--quick]``."""

import argparse
import sys

from .studies import demo


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m rigidfem", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="Kane's spin-up beam, nonlinear and linear models: a summary and a plot")
    d.add_argument("--t-end", type=float, default=30.0, help="simulated time in s (default 30)")
    d.add_argument("--output", default="rigidfem_demo.png", help="plot file (default rigidfem_demo.png)")
    b = sub.add_parser("bench", help="work-precision study of the standard scenes and integrators")
    b.add_argument("--output", default="bench", help="directory for work_precision.csv/.png and discretisation.csv")
    b.add_argument("--quick", action="store_true", help="fewer settings and smaller scenes (a smoke run)")
    args = parser.parse_args(argv)
    if args.command == "demo":
        demo.run(t_end=args.t_end, output=args.output)
    elif args.command == "bench":
        from .studies import study

        study.bench(args.output, quick=args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
