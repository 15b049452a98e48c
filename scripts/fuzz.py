#!/usr/bin/env python
"""Fuzz rigidfem's calling contract: random models and random calls, each case in a worker
process (crashes and hangs caught), outcomes tallied by the class of call.

    python scripts/fuzz.py --minutes 15 --report              # a campaign with random seeds
    python scripts/fuzz.py --minutes 15 --report --minimize --save   # ... minimise new violations into the corpus
    python scripts/fuzz.py --replay tests/fuzz_corpus         # re-run the saved cases
    python scripts/fuzz.py --show tests/fuzz_corpus/x.json    # a saved case as a script
    FUZZ_PACKAGE=/tmp/pkg python scripts/fuzz.py ...          # fuzz another build (an unpacked wheel)

The contract, the generators and the worker protocol are in tests/fuzz_contract.py; the suite's
fixed-seed run is tests/test_contract.py.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import fuzz_contract as fc  # noqa: E402


def campaign(args) -> int:
    features = [f for f in fc.FEATURES if not (args.skip_pending and f in fc.PENDING)]
    base_seed = args.seed if args.seed is not None else random.SystemRandom().randrange(2**31)
    start = time.monotonic()
    deadline = start + 60.0 * args.minutes if args.cases is None else None
    print(f"fuzz: seed {base_seed}, {args.workers} workers, "
          f"{f'{args.cases} cases' if args.cases else f'{args.minutes} min'}, timeout {args.timeout} s per case"
          f"{', pending features left out' if args.skip_pending else ''}", flush=True)
    tally = fc.Tally()
    cases = []

    def drawn(source):
        for case in source:
            cases.append(case)
            yield case

    last = time.monotonic()
    with fc.Runner(workers=args.workers, timeout=args.timeout) as runner:
        source = fc.background(fc.stream(args.cases, base_seed, features, batch=args.batch))
        for index, result in runner.run(drawn(source), deadline=deadline):
            case = cases[index]
            for v in tally.add(case, result):
                if tally.counts[v["signature"]] == 1:
                    known = fc.known_issue(case, v)
                    print(f"  [{time.monotonic() - start:6.0f} s] {'known' if known else 'NEW  '} {v['signature']}",
                          flush=True)
            if time.monotonic() - last > 60:
                last = time.monotonic()
                print(f"  [{last - start:6.0f} s] {tally.cases} cases, {sum(r['calls'] for r in tally.rows.values())} "
                      f"calls, {len(tally.found)} distinct violations, {runner.restarts} worker restarts", flush=True)
        restarts = runner.restarts
        package = runner.package
    wall = time.monotonic() - start
    calls = sum(r["calls"] for r in tally.rows.values())
    print(f"\n{tally.cases} cases, {calls} calls in {wall:.0f} s ({tally.cases / max(wall, 1e-9):.1f} cases/s), "
          f"{restarts} worker restarts; the workers imported rigidfem from {package}\n")
    if args.report:
        print(tally.table())
        print()
    report_violations(tally, args)
    if args.json:
        Path(args.json).write_text(json.dumps({"table": {k: dict(v) for k, v in tally.rows.items()},
                                               "cases": tally.cases, "counts": dict(tally.counts),
                                               "found": tally.found}, indent=1))
    return 1 if tally.found else 0


def report_violations(tally, args):
    if not tally.found:
        print("no contract violation found")
        return
    new, known = [], {}
    for sig, n in sorted(tally.counts.items(), key=lambda kv: (-kv[1], kv[0])):
        entry = tally.found[sig]
        what = fc.known_issue(entry["case"], entry["violation"])
        (known.setdefault(what, []) if what else new).append((sig, n))
    print(f"{len(tally.found)} distinct violations (kind|function|exception): {len(new)} new, "
          f"{len(tally.found) - len(new)} of {len(known)} known issues\n")
    print("NEW\n")
    for sig, n in new:
        describe(tally, sig, n, None, args)
    print("KNOWN (being fixed): one example each\n")
    for what, sigs in known.items():
        total = sum(n for _, n in sigs)
        print(f"* {what}: {len(sigs)} signatures, {total} calls: " + ", ".join(s for s, _ in sigs[:6]) +
              (" ..." if len(sigs) > 6 else ""))
        describe(tally, sigs[0][0], sigs[0][1], what, args)


def describe(tally, sig, n, known, args):
    entry = tally.found[sig]
    case, v = entry["case"], entry["violation"]
    print(f"- {sig}  x{n}  ({case.get('origin', '')})")
    step = case["steps"][v["step"]] if 0 <= v["step"] < len(case["steps"]) else None
    if step:
        print(f"    culprit: {fc.render_step(step)[:300]}")
    print(f"    outcome: {v['detail'][:300]}")
    if v["kind"] in ("crash", "hang"):  # pin the culprit: does it die alone, in a fresh worker?
        again = fc.violations(case, fc.run_one(case, args.timeout))
        alone = any(w["signature"] == sig for w in again)
        print(f"    alone in a fresh worker: {'reproduces' if alone else 'does NOT reproduce (needs the cases before it)'}")
    if args.minimize:
        t = time.monotonic()
        small = fc.minimize(case, sig, timeout=args.timeout, budget=args.minimize_budget)
        print(f"    minimised to {len(small['steps'])} steps in {time.monotonic() - t:.0f} s:")
        for line in fc.render(small, numbered=False).split("# --- the case " + "-" * 80 + "\n", 1)[1].splitlines():
            print("      " + line)
        if args.save:
            path = fc.save(small, v, known=known)
            print(f"    saved {os.path.relpath(path)}")
    print()


def replay(args) -> int:
    paths = []
    for p in args.replay:
        p = Path(p)
        paths += sorted(p.glob("*.json")) if p.is_dir() else [p]
    entries = [(p, json.loads(p.read_text())) for p in paths]
    if not entries:
        print("no saved cases")
        return 0
    failing = 0
    with fc.Runner(workers=args.workers, timeout=args.timeout) as runner:
        results = dict(runner.run([e["case"] for _, e in entries]))
    for k, (path, entry) in enumerate(entries):
        vs = fc.violations(entry["case"], results[k])
        same = [v for v in vs if v["signature"] == entry["signature"]]
        state = "STILL VIOLATES" if same else ("other violation" if vs else "passes")
        failing += bool(vs)
        print(f"{state:15} {path.name}  [{entry.get('status')}{', known: ' + entry['known'] if entry.get('known') else ''}]")
        for v in vs:
            print(f"                  {v['signature']}: {v['detail'][:200]}")
    return 1 if failing else 0


def show(args) -> int:
    for p in args.show:
        entry = json.loads(Path(p).read_text())
        print(f"# {entry['signature']}\n# {entry['detail']}\n")
        print(fc.render(entry["case"]))
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--minutes", type=float, default=1.0, help="wall time of the campaign")
    ap.add_argument("--cases", type=int, default=None, help="a fixed number of cases instead of a time budget")
    ap.add_argument("--seed", type=int, default=None, help="base seed (default: random); batch k uses seed + k")
    ap.add_argument("--batch", type=int, default=50, help="cases drawn per hypothesis run")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds per case before it counts as a hang")
    ap.add_argument("--report", action="store_true", help="print the table of outcomes by class of call")
    ap.add_argument("--skip-pending", action="store_true", help="leave out the features of fuzz_contract.PENDING")
    ap.add_argument("--minimize", action="store_true", help="minimise each distinct violation")
    ap.add_argument("--minimize-budget", type=float, default=60.0, help="seconds per violation")
    ap.add_argument("--save", action="store_true", help="save minimised violations to tests/fuzz_corpus")
    ap.add_argument("--replay", nargs="+", help="re-run saved cases (files or folders)")
    ap.add_argument("--show", nargs="+", help="print saved cases as scripts")
    ap.add_argument("--json", help="also write the table and the violations (with their cases) to this file")
    args = ap.parse_args(argv)
    if args.show:
        return show(args)
    if args.replay:
        return replay(args)
    return campaign(args)


if __name__ == "__main__":
    sys.exit(main())
