"""The calling contract on random models and calls (issue 10), and the saved evidence.

Every call of the public API must return finite numbers, raise ValueError("name: ..."),
rigidfem.SimulationError naming the time and cause, or TypeError for a wrong number of arguments;
never crash, hang, leak another exception, accept a bad argument or return NaN from finite inputs.
The cases (random trees of bodies with every joint type, beams, drives, loads, and random calls
with good and deliberately bad arguments) are drawn by hypothesis from a fixed seed and run in
worker processes; see tests/fuzz_contract.py. ``scripts/fuzz.py`` runs longer campaigns.

The generators of the violations being fixed (fuzz_contract.PENDING) are left out here, and the
saved cases of open violations (tests/fuzz_corpus, "status": "open") are expected to fail until
they are fixed; set their status to "fixed" then, so that they guard against a relapse.

Environment: ``RIGIDFEM_CONTRACT_BUDGET`` (s, default 55) is the wall time after which no new random
case starts; the number of cases drawn (2000 at the default) grows in proportion to it, so a slower
build (scripts/sanitize.sh: ASan + UBSan) given a larger budget runs as many cases or more, a faster
machine given a larger budget runs more. ``RIGIDFEM_CONTRACT_TIMEOUT`` (s per case, default 15) is the
time after which a case counts as a hang; raise it with the budget for a sanitizer build. The cases
are a prefix of one derandomised stream: a longer run repeats a shorter one's cases first.
"""

import os
import time

import pytest

import fuzz_contract as fc


def _seconds(variable: str, default: float) -> float:
    """A positive number of seconds from the environment variable, else the default."""
    text = os.environ.get(variable, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{variable}: expected a positive number of seconds, got {text!r}") from None
    if not 0.0 < value < float("inf"):
        raise ValueError(f"{variable}: expected a positive number of seconds, got {text!r}")
    return value


SEED = 20261110
DEFAULT_BUDGET = 55.0
BUDGET = _seconds("RIGIDFEM_CONTRACT_BUDGET", DEFAULT_BUDGET)  # s: no new case after this (a prefix of the stream)
CASES = 50 * max(40, round(40 * BUDGET / DEFAULT_BUDGET))  # whole batches of 50; 2000: about 45 s on two cores
TIMEOUT = _seconds("RIGIDFEM_CONTRACT_TIMEOUT", 15.0)     # s per case before it counts as a hang


def _explain(tally, limit=12):
    lines = []
    for sig, n in sorted(tally.counts.items(), key=lambda kv: -kv[1])[:limit]:
        entry = tally.found[sig]
        case, v = entry["case"], entry["violation"]
        step = case["steps"][v["step"]] if 0 <= v["step"] < len(case["steps"]) else None
        lines.append(f"{sig}  x{n}\n    {fc.render_step(step)[:300] if step else ''}\n    -> {v['detail'][:300]}")
    first = next(iter(tally.found.values()))
    lines.append("reproducer of the first (python scripts/fuzz.py --minimize shrinks it):\n" +
                 fc.render(first["case"]).split("# --- the case " + "-" * 80 + "\n", 1)[1])
    return "\n".join(lines)


def test_random_cases_keep_the_contract():
    features = [f for f in fc.FEATURES if f not in fc.PENDING]
    start = time.monotonic()
    cases, tally = [], fc.Tally()

    def drawn(source):
        for case in source:
            cases.append(case)
            yield case

    with fc.Runner(workers=2, timeout=TIMEOUT) as runner:
        for index, result in runner.run(drawn(fc.background(fc.stream(CASES, SEED, features))),
                                        deadline=start + BUDGET):
            tally.add(cases[index], result)
    print(f"\n{tally.table()}\n({time.monotonic() - start:.1f} s, {tally.cases} of {CASES} cases)")
    assert tally.cases >= min(200, CASES), f"only {tally.cases} cases ran within the budget"
    for sig, entry in list(tally.found.items()):  # known, from what a run does (not from an input group)
        if fc.pending_outcome(entry["violation"], entry["case"]):
            del tally.found[sig], tally.counts[sig]
    assert not tally.found, _explain(tally)


CORPUS = fc.load_corpus()


@pytest.fixture(scope="module")
def corpus_results():
    with fc.Runner(workers=2, timeout=TIMEOUT) as runner:
        return dict(runner.run([entry["case"] for _, entry in CORPUS]))


@pytest.mark.parametrize("k", range(len(CORPUS)), ids=[p.stem for p, _ in CORPUS])
def test_saved_case(k, corpus_results):
    """A saved violation: "open" ones are expected to violate still (any violation: a crash may turn
    into a hang, say); once a case passes, set its status to "fixed" and it guards the fix."""
    path, entry = CORPUS[k]
    found = fc.violations(entry["case"], corpus_results[k])
    if found and entry.get("status") == "open":
        pytest.xfail(f"open: {entry['signature']} ({entry.get('known') or 'new'})")
    script = "\n".join(entry["script"])
    assert not found, f"{path.name}:\n{script}\n" + "\n".join(f"{v['signature']}: {v['detail']}" for v in found)
