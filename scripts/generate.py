"""Generate and validate puzzle specs.

    python scripts/generate.py paper --split {train,test,all} --out DIR     # DIR/<name>.json
    python scripts/generate.py chain --kinds door,slide,wheel --seed S --out FILE
    python scripts/generate.py random --components N --seed S [--multi-locker] [--kinds paper|all] --out FILE
                                      [--require-kinds KIND,...]     # every box holds each kind named
    python scripts/generate.py random|chain ... --count N --out DIR [--workers K | --ray auto|ADDRESS]
    python scripts/generate.py validate FILE...     # exit 1 and one line per problem if any is invalid
    python scripts/generate.py mjcf SPEC --out DIR [--box-only] [--locks {contact,latch}]
                                                    # DIR/scene.xml (or DIR/box.xml) + assets, loadable by mujoco
    python scripts/generate.py check-locks SPEC... [--with-robot] [--locks {contact,latch}] [--json FILE]
                                               [--stops-only]
                                                    # exit 1 if a model alone does not hold its lock rules
    python scripts/generate.py mesh SPEC --out DIR  # DIR/<name>.glb|.obj|.stl + <name>-<part>.stl

``mjcf`` writes the table, the robot and the box (``scene.xml``), or with ``--box-only`` the box alone
(``box.xml``, the lid frame at the world origin: ``models.box_export``). ``--locks contact`` (the default) makes
the spec's lock rules mechanisms that block by contact; a rule no mechanism realizes is named on one line (the
twin holds it with a latch; in ``box.xml`` nothing holds it). ``--locks latch`` builds no mechanism at all.

``check-locks`` pushes every part of each box from every state reachable from all-closed, in plain MuJoCo, with the
box alone (or with ``--with-robot`` in the whole scene), and compares what moved with what the spec allows
(``models.lock_check``), the parts not pushed resting at their end stops and at 10 % and 20 % of their travel inside
their states' bands (the band check: the twin counts a part closed below 25 % and open above 75 %, and a locker
anywhere there must hold or free as its state says; ``--stops-only``: at the stops alone): one line per box
(transitions that agree, a held part's largest play, how far it went before its lock caught it [% of its travel;
held: below 50 %], rules without a mechanism), one
indented line per disagreement, then a total. Exit 1 if any transition disagrees, 2 if a spec is invalid (one line
each) or a box cannot be built. ``--json FILE`` writes every box's result (moves as fractions of the travel).

``mesh`` exports the box as the MuJoCo model has it (at start, every component closed): one part per
component plus ``box`` (the shell) and one per lock mechanism's piece (``<A>-interlocks-<B>-wall``, ``-rod``;
``<A>-latches-<B>-tooth``, ``-lug``), each one watertight solid, in the lid frame (origin at the centre of the
lid's top face, z up), in metres; STL has no part names, hence one STL per part beside the merged one
(``models.mesh_export``).

``--plot`` on paper/chain/random also writes a top view of each layout (PNG beside the JSON).
Generated boxes stand where the robot reaches every handle (at most 28 components fit); ``--anywhere``
on chain/random keeps the default pose whatever it leaves out of reach, for the symbolic simulator.

``--count N`` on chain/random writes a dataset: N specs with seeds S..S+N-1 in the directory ``--out``
(``<name>.json`` each) and ``manifest.json`` (name, seed, file, SHA-256, shortest solution), generated
in parallel (``--workers K``, default one per core for 64 specs or more; ``--ray auto|ADDRESS``).

Every generated file is a pure function of the arguments: the same command writes the same bytes (with
any number of workers).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable
from pathlib import Path

from tqdm import tqdm

from puzzlebox.lab.box_exports import export_box_meshes, export_mjcf
from puzzlebox.lab.cli import OneLineParser, fail, run_script, write_json
from puzzlebox.lab.errors import LabError, SpecFilesInvalid
from puzzlebox.lab.inputs import check_seed
from puzzlebox.lab.spec_files import load_box_specs, validation_lines, write_spec_file
from puzzlebox.lab.spec_generators import chain_settings, generate_spec, random_settings
from puzzlebox.models import ModelsError
from puzzlebox.models.generator import paper_family
from puzzlebox.models.mechanism_mjcf import LOCK_MODES


def _paper(args: argparse.Namespace) -> None:
    for spec in paper_family(args.split, seed=check_seed(args.seed)):
        _print(write_spec_file(spec, Path(args.out) / f"{spec.name}.json", args.plot))


def _kind_list(text: str | None) -> tuple[str, ...]:
    """``--require-kinds door,slide``: the kinds, in order, each once (the generator refuses an unknown one)."""
    return tuple(dict.fromkeys(k.strip() for k in text.split(",") if k.strip())) if text else ()


def _generated(args: argparse.Namespace) -> int | None:
    """chain or random: a spec in the file ``--out``, or with ``--count N`` a dataset in the directory ``--out``."""
    if args.verb == "chain":
        generator = chain_settings(args.kinds)
    else:
        generator = random_settings(args.components, args.multi_locker, args.kinds, _kind_list(args.require_kinds))
    if args.count is None:
        spec = generate_spec(generator, seed=args.seed, name=args.name, anywhere=args.anywhere)
        return _print(write_spec_file(spec, Path(args.out), args.plot))
    from puzzlebox.lab.dataset_run import make_dataset  # the runner only when asked

    run = make_dataset(args.out, generator, seed=args.seed, count=args.count, name=args.name,
                       anywhere=args.anywhere, plot=args.plot, workers=args.workers, ray=args.ray)  # fmt: skip
    if run.manifest is None:
        print(f"stopped: {run.written} of {run.count} spec(s) written in {run.out}; no manifest", file=sys.stderr)
        return 130
    print(f"wrote {run.written} specs and {run.manifest}")


def _check_locks(args: argparse.Namespace) -> int:
    """Exit 1 if any transition disagrees, 2 if a spec is invalid (one line each) or a box cannot be built."""
    from puzzlebox.lab.lock_checks import LockChecks  # MuJoCo only when asked

    try:
        specs = load_box_specs(args.specs)  # every file read before any box is built
    except SpecFilesInvalid as err:
        for problem in err.problems[:-1]:
            print(f"error: {problem}", file=sys.stderr)
        fail(err.problems[-1])  # one line per invalid file, exit 2
    from puzzlebox.models.lock_check import BAND_OFFSETS

    checks = LockChecks(args.locks, args.with_robot, (0.0,) if args.stops_only else BAND_OFFSETS)
    checks.run(tqdm(specs, desc="check-locks", unit="box", disable=None), say=tqdm.write,
               warn=lambda line: tqdm.write(line, file=sys.stderr))  # fmt: skip
    if args.json:
        print(f"wrote {write_json(Path(args.json), checks.record())}")
    print(checks.total_line())
    return checks.exit_code


def _print(lines: Iterable[str]) -> None:
    for line in lines:
        print(line)


def _validate(args: argparse.Namespace) -> int:
    invalid = 0
    for file in args.files:
        lines, valid = validation_lines(file)
        _print(lines)
        invalid += not valid
    if invalid:
        print(f"{invalid} of {len(args.files)} file(s) invalid", file=sys.stderr)
    return 1 if invalid else 0


def _generator_flags(parser: argparse.ArgumentParser, name_from: str) -> None:
    """The flags chain and random share: the output, the name, the plot, the pose, and those of a dataset."""
    parser.add_argument("--out", required=True, help="output JSON file")
    parser.add_argument("--name", default=None, help=f"spec name (default: derived from {name_from} and seed)")
    parser.add_argument("--plot", action="store_true", help="also write a top-view PNG beside each JSON")
    parser.add_argument("--anywhere", action="store_true", help="keep the box at the default pose even if the robot "
                        "cannot reach every handle (symbolic only)")  # fmt: skip
    parser.add_argument("--count", type=int, default=None, help="N specs, seeds S..S+N-1: --out is a directory")
    parser.add_argument("--workers", type=int, default=None, help="with --count: worker processes (default: cores)")
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="with --count: generate on Ray")


def main(argv: list[str] | None = None) -> int:
    locks = {"choices": LOCK_MODES, "default": "contact", "help": "lock rules as mechanisms that block by contact "
             "(default) or as latches alone (no mechanism)"}  # fmt: skip
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    verbs = parser.add_subparsers(dest="verb", required=True)

    paper = verbs.add_parser("paper", help="the paper's 12 five-component chains (train 9 / test 3)")
    paper.add_argument("--split", choices=("train", "test", "all"), required=True)
    paper.add_argument("--out", required=True, help="directory; one DIR/<name>.json per variant")
    paper.add_argument("--seed", type=int, default=0, help="layout seed (default 0: the reference boxes)")
    paper.add_argument("--plot", action="store_true", help="also write a top-view PNG beside each JSON")
    paper.set_defaults(run=_paper)

    chain = verbs.add_parser("chain", help="a chain of any registered kinds whose neighbours may lock each other")
    chain.add_argument("--kinds", required=True, help="comma-separated, e.g. door,slide,wheel")
    chain.add_argument("--seed", type=int, required=True)
    _generator_flags(chain, "kinds")
    chain.set_defaults(run=_generated)

    rand = verbs.add_parser("random", help="a random solvable lock graph of N components")
    rand.add_argument("--components", type=int, required=True)
    rand.add_argument("--seed", type=int, required=True)
    rand.add_argument("--multi-locker", action="store_true", help="some components get two lockers")
    rand.add_argument("--kinds", choices=("paper", "all"), default="paper", help="kinds drawn: the paper's "
                      "door/slide/wheel (default) or every registered kind (models.kinds)")  # fmt: skip
    rand.add_argument("--require-kinds", default=None, metavar="KIND,...", help="kinds every box holds at least one "
                      "of, comma-separated (e.g. door,slide,wheel,lever,drawer with --kinds all)")  # fmt: skip
    _generator_flags(rand, "N")
    rand.set_defaults(run=_generated)

    scene = verbs.add_parser("mjcf", help="the MuJoCo scene of a spec: DIR/scene.xml (or DIR/box.xml) + assets")
    scene.add_argument("spec", help="puzzle spec file")
    scene.add_argument("--out", required=True, help="output directory")
    scene.add_argument("--box-only", action="store_true", help="the box alone, lid frame at the origin: DIR/box.xml")
    scene.add_argument("--locks", **locks)
    scene.set_defaults(run=lambda args: _print(export_mjcf(args.spec, args.out, args.box_only, args.locks)))

    check = verbs.add_parser("check-locks", help="does each box's model alone hold its lock rules? exit 1 if not")
    check.add_argument("specs", nargs="+", metavar="SPEC", help="puzzle spec files")
    check.add_argument("--with-robot", action="store_true", help="check the whole scene (table, robot, box)")
    check.add_argument("--locks", **locks)
    check.add_argument("--json", default=None, metavar="FILE", help="also write every box's result to FILE")
    check.add_argument("--stops-only", action="store_true", help="rest the parts not pushed at their end stops "
                       "only (default: also 10 %% and 20 %% inside their states' bands, where the twin already counts "
                       "them in their states)")  # fmt: skip
    check.set_defaults(run=_check_locks)

    mesh = verbs.add_parser("mesh", help="the box as meshes: DIR/<name>.glb, .obj, .stl and one STL per part "
                            "(shell, components, mechanisms)")  # fmt: skip
    mesh.add_argument("spec", help="puzzle spec file")
    mesh.add_argument("--out", required=True, help="output directory")
    mesh.set_defaults(run=lambda args: _print(export_box_meshes(args.spec, args.out)))

    validate = verbs.add_parser("validate", help="check spec files; exit 1 if any is invalid")
    validate.add_argument("files", nargs="+")
    validate.set_defaults(run=_validate)

    args = parser.parse_args(argv)
    if getattr(args, "count", None) is None and (getattr(args, "workers", None) or getattr(args, "ray", None)):
        fail("--workers and --ray go with --count (a dataset)")
    try:
        return args.run(args) or 0
    except (LabError, ModelsError) as err:
        fail(str(err))
    except OSError as err:
        fail(f"cannot write output: {err}")
    return 0


if __name__ == "__main__":
    run_script(main)
