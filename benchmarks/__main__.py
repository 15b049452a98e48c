"""``python -m benchmarks {scaling,peers,scale,loops,implicit_step,sweep,kane_peers,loop_peers,sweep_peers,strip_peers,crane_peers,size_peers,evaluations,orders,tolerance,accuracy,viewer,sensitivities,contact,energy,core_builds} [--quick] [--output DIR]``, from the root of a checkout."""

from __future__ import annotations

import argparse
import importlib
import sys

#: Command -> its help; each command is a module of this package with ``run(output_dir, quick)``.
COMMANDS = {
    "scaling": "forward-dynamics and implicit-step cost against the number of coordinates",
    "peers": "rigidfem against Pinocchio and MuJoCo (needs: pip install pin mujoco)",
    "scale": "hidden costs at scale: Python calls against C++, outputs, building long beams",
    "loops": "closed loops: cost per step against n and the number of constraint rows, against a dense solve",
    "implicit_step": "where a generalised-alpha step's time goes on Kane's beam (m = 10 ... 1000): floor and parts",
    "sweep": "rf.sweep on 1 and 2 threads, 2 processes and a 2-worker Dask LocalCluster (needs dask[distributed])",
    "kane_peers": "Kane's spin-up beam (m = 20, 40): CPU time to a tip error against Exudyn and MuJoCo (needs: pip install exudyn mujoco)",
    "loop_peers": "closed loops (a slider-crank with a flexible rod, a Bricard linkage): CPU time to a point error and the closure kept, against Exudyn and MuJoCo (needs: pip install exudyn mujoco)",
    "sweep_peers": "64 runs of Kane's beam on 2 cores: rf.sweep (threads, processes, Dask) against Exudyn's ParameterVariation and MuJoCo's rollout, wall time at 1e-4 m (needs: pip install exudyn mujoco dask[distributed])",
    "strip_peers": "a whippy strip released from rest (m = 16, 32, 64): CPU time to a tip error against Exudyn (KinematicTree, ANCF cable) and MuJoCo (chain, flex rod) (needs: pip install exudyn mujoco)",
    "crane_peers": "an offshore crane with a hoisting rope on a moving base: CPU time to a payload error against Exudyn (KinematicTree, rope by a symbolic spring law, base by coordinate constraints) and MuJoCo (tendon rope, servoed base) (needs: pip install exudyn mujoco)",
    "size_peers": "size: one second of a whippy strip of 10^3 and 10^4 rfes, CPU time to a tip error against Exudyn (the chain in redundant coordinates, sparse solver) and MuJoCo (the chain by MjSpec) (needs: pip install exudyn mujoco)",
    "evaluations": "one evaluation of each kind per model (forward dynamics, rk4 step, implicit Newton iteration) on the peers pages' models (slider-crank, Bricard, strip, crane) against MuJoCo's mj_forward and mj_step and Pinocchio's ABA, and where rigidfem's forward dynamics goes (needs: pip install mujoco; pin optional)",
    "orders": "speed against error on Kane's beam: esdirk43, radau5, generalised-α and dopri5",
    "tolerance": "Kane's beam (m = 20): tip error delivered against rtol asked, every adaptive method; fixed-step failures",
    "accuracy": "the default asked for a tip error against the best of every method: strips, tapes, the bench's scenes",
    "viewer": "the 3D viewer: build time, HTML size and time per frame in headless Chromium (needs chromium)",
    "sensitivities": "forward sensitivities: cost per parameter against the run, strips of m = 20, 80, 320",
    "work_precision": "python -m rigidfem bench as pages: the standard scenes under the standard integrators (least time to a tip error, auto against the best) and the discretisation error",
    "energy": "conservative mechanisms over long runs (pendulums, a four-bar, the Bricard linkage): the energy error early and late by gauss6, radau5, rk4, generalised-α (ρ∞ = 1) and dop853",
    "core_builds": "the portable and the x86-64-v3 build of the C++ core side by side: forward dynamics on the peers pages' models and the README's run (needs an x86-64-v3 processor and: pip install mujoco)",
    "contact": "contact at scale: a strip of m rfes on the ground, a capsule per rfe: forward dynamics and Jacobians",
    "limits": "where radau5's cheapest runs go on the peers page's rows under the lead asked (the strip at m = 16 to 1e-6 m, the crane to 1e-4): counts, residuals and tangents at their cost per call, the strip's modes in its motion",
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for name, text in COMMANDS.items():
        p = sub.add_parser(name, help=text, description=text)
        p.add_argument("--output", default="bench", help="folder for the tables, CSV and a markdown page each (default bench; docs/benchmarks: the site's pages)")
        p.add_argument("--quick", action="store_true", help="a few small sizes and settings (a smoke run)")
    args = parser.parse_args(argv)
    try:
        module = importlib.import_module(f"{__package__ or 'benchmarks'}.{args.command}")
        common = importlib.import_module(f"{__package__ or 'benchmarks'}._common")
        common.start("python -m benchmarks " + " ".join(argv if argv is not None else sys.argv[1:]))
        module.run(args.output, quick=args.quick)
    except ImportError as e:  # a peer code (or rigidfem) not installed: say what to install
        parser.exit(1, f"{parser.prog} {args.command}: {e}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
