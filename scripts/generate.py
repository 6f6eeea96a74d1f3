"""Generate and validate puzzle specs.

    python scripts/generate.py paper --split {train,test,all} --out DIR     # DIR/<name>.json
    python scripts/generate.py chain --kinds door,slide,wheel --seed S --out FILE
    python scripts/generate.py random --components N --seed S [--multi-locker] [--kinds paper|all] --out FILE
    python scripts/generate.py random|chain ... --count N --out DIR [--workers K | --ray auto|ADDRESS]
    python scripts/generate.py validate FILE...     # exit 1 and one line per problem if any is invalid
    python scripts/generate.py mjcf SPEC --out DIR [--box-only] [--locks {contact,latch}]
                                                    # DIR/scene.xml (or DIR/box.xml) + assets, loadable by mujoco
    python scripts/generate.py check-locks SPEC... [--with-robot] [--locks {contact,latch}] [--json FILE]
                                                    # exit 1 if a model alone does not hold its lock rules
    python scripts/generate.py mesh SPEC --out DIR  # DIR/<name>.glb|.obj|.stl + <name>-<part>.stl

``mjcf`` writes the table, the robot and the box (``scene.xml``), or with ``--box-only`` the box alone
(``box.xml``, the lid frame at the world origin: ``models.box_export``). ``--locks contact`` (the default) makes
the spec's lock rules mechanisms that block by contact; a rule no mechanism realizes is named on one line (the
twin holds it with a latch; in ``box.xml`` nothing holds it). ``--locks latch`` builds no mechanism at all.

``check-locks`` pushes every part of each box from every state reachable from all-closed, in plain MuJoCo, with
the box alone (or with ``--with-robot`` in the whole scene), and compares what moved with what the spec allows
(``models.lock_check``): one line per box (transitions that agree, how far a held part moved at most [% of its
travel], rules without a mechanism), one indented line per disagreement, then a total. Exit 1 if any transition
disagrees, 2 if a spec is invalid (one line each) or a box cannot be built. ``--json FILE`` writes every box's
result (moves as fractions of the travel).

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
import dataclasses
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from tqdm import tqdm

from puzzlebox.lab.cli import fail, one_line
from puzzlebox.models import LockRule, LockTable, ModelsError, PuzzleSpec, SpecError, load_spec, save_spec
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random, paper_family
from puzzlebox.models.kinds import family_named
from puzzlebox.models.mechanism_mjcf import LOCK_MODES, mechanism_layout

if TYPE_CHECKING:
    import mujoco

    from puzzlebox.models.lock_check import LockCheck


def _write(spec: PuzzleSpec, path: Path, plot: bool) -> None:
    print(f"wrote {save_spec(spec, path)}  ({'-'.join(spec.kinds)})")
    if plot:
        from puzzlebox.lab.spec_plot import plot_spec  # matplotlib only when asked

        print(f"wrote {plot_spec(spec, path.with_suffix('.png'))}")


def _paper(args: argparse.Namespace) -> None:
    for spec in paper_family(args.split, seed=args.seed):
        _write(spec, Path(args.out) / f"{spec.name}.json", args.plot)


def _chain(args: argparse.Namespace) -> None:
    kinds = [k.strip() for k in args.kinds.split(",") if k.strip()]
    if args.count is not None:
        return _dataset(args, {"generator": "chain", "kinds": kinds})
    box = BoxConfig(fit_reach=not args.anywhere)
    _write(generate_chain(kinds, seed=args.seed, name=args.name, box=box), Path(args.out), args.plot)


def _dataset(args: argparse.Namespace, generator: dict) -> None:
    """``--count N``: N specs (seeds S..S+N-1) and a manifest in the directory ``--out``, made in parallel."""
    from puzzlebox.lab.dataset import spec_task, write_manifest, write_spec
    from puzzlebox.lab.interrupt import StopRequests
    from puzzlebox.learning.runner import RunnerError, make_executor

    if args.count < 1:
        fail(f"--count must be >= 1, got {args.count}")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        fail(f"--out {out} is a file; with --count it names a directory")
    generator = {**generator, "name": args.name, "anywhere": args.anywhere, "seed": args.seed}
    tasks = [spec_task(f"s{args.seed + i}", {**generator, "seed": args.seed + i}) for i in range(args.count)]
    entries = []
    try:
        executor = make_executor(args.workers or (1 if args.count < 64 else None), args.ray)
        with StopRequests("spec") as stop, executor:
            bar = tqdm(total=len(tasks), desc=f"{generator['generator']} specs", unit="spec", disable=None)
            for done in executor.run(tasks, lambda: stop.requested):
                if not done.ok:
                    fail(f"seed {done.task.settings['seed']}: {str(done.payload).splitlines()[0]}")
                path = write_spec(out, done.payload)
                if args.plot:
                    from puzzlebox.lab.spec_plot import plot_spec

                    plot_spec(load_spec(path), path.with_suffix(".png"))
                entries.append(done.payload["entry"])
                bar.update()
            bar.close()
    except RunnerError as err:
        fail(str(err))
    if len(entries) < len(tasks):
        print(f"stopped: {len(entries)} of {len(tasks)} spec(s) written in {out}; no manifest", file=sys.stderr)
        return 130
    path = write_manifest(out, {**generator, "seed": args.seed, "count": args.count}, entries)
    print(f"wrote {len(entries)} specs and {path}")


def _random(args: argparse.Namespace) -> None:
    if args.count is not None:
        settings = {"components": args.components, "multi_locker": args.multi_locker, "kinds": args.kinds}
        return _dataset(args, {"generator": "random", **settings})
    config = RandomGraphConfig(args.components, multi_locker=args.multi_locker, family=family_named(args.kinds))
    box = BoxConfig(fit_reach=not args.anywhere)
    _write(generate_random(config, seed=args.seed, name=args.name, box=box), Path(args.out), args.plot)


def _box_spec(file: str) -> PuzzleSpec | str:
    """The puzzle-box spec in ``file``, or the one-line reason it is none (invalid, or a spec with no box)."""
    try:
        spec = load_spec(file)
    except SpecError as err:
        return one_line(err)
    if spec.box is None:
        return f"{file}: spec {spec.name!r} is a disassembly scene (no box); only puzzle boxes build as MuJoCo models"
    return spec


def _load_box_spec(file: str) -> PuzzleSpec:
    """:func:`_box_spec`, or ``fail`` with its reason."""
    spec = _box_spec(file)
    if isinstance(spec, str):
        fail(spec)
    return spec


def _rule_text(rule: LockRule) -> str:
    return f"{rule.locker}={rule.locker_state} holds {rule.locked}={rule.locked_state}"


def _latch_only(spec: PuzzleSpec, locks: str) -> list[tuple[LockRule, str]]:
    """The rules of ``spec`` no mechanism realizes with ``locks`` (every rule with ``latch``), each with why."""
    if locks == "latch":
        return [(rule, "--locks latch: no mechanism") for rule in spec.locks]
    return [(u.rule, u.reason) for u in mechanism_layout(spec).unrealized]


def _mjcf(args: argparse.Namespace) -> None:
    spec = _load_box_spec(args.spec)
    try:
        if args.box_only:
            from puzzlebox.models.box_export import export_box  # MuJoCo only when asked

            path = export_box(spec, args.out, locks=args.locks)
        else:
            from puzzlebox.models.scene import SceneConfig, build_scene

            path = build_scene(spec, SceneConfig(locks=args.locks)).export(args.out)
    except ModelsError as err:  # an unknown kind, a box pose out of the robot's reach
        fail(f"{args.spec}: {one_line(err)}")
    print(f"wrote {path} and its assets ({len(list(Path(args.out).iterdir())) - 1} files)")
    unrealized = _latch_only(spec, args.locks)
    if unrealized:  # a rule the model alone does not hold: say so
        rules = "; ".join(f"{_rule_text(rule)} ({reason})" for rule, reason in unrealized)
        print(f"{len(unrealized)} rule(s) enforced by latches only in the twin: {rules}")


def _check_locks(args: argparse.Namespace) -> int:
    """Push every part of each box from every reachable state (``models.lock_check``): one line per box, one per
    disagreement; exit 1 if any transition disagrees, 2 if a box could not be built."""
    from puzzlebox.lab.cli import write_json
    from puzzlebox.models.lock_check import check_locks  # MuJoCo only when asked

    loaded = [(file, _box_spec(file)) for file in args.specs]  # every file read before any box is built
    problems = [spec for _, spec in loaded if isinstance(spec, str)]
    for problem in problems[:-1]:
        print(f"error: {problem}", file=sys.stderr)
    if problems:
        fail(problems[-1])  # one line per invalid file, exit 2
    specs = [(file, spec) for file, spec in loaded if not isinstance(spec, str)]
    boxes, errors = [], []
    for file, spec in tqdm(specs, desc="check-locks", unit="box", disable=None):
        try:
            model, joints = _compiled(spec, args.locks, args.with_robot)
        except ModelsError as err:
            errors.append({"file": str(file), "spec": spec.name, "error": one_line(err)})
            tqdm.write(f"error: {file}: {one_line(err)}", file=sys.stderr)
            continue
        result = check_locks(spec, model, joints)
        box = _box_record(file, spec, result, _latch_only(spec, args.locks))
        boxes.append(box)
        tqdm.write(_box_line(box))
        for t in box["disagreements"]:
            opened = ", ".join(t["open"]) or "none"
            moved = f"moved {100 * t['moved']:.1f} % of its travel"
            tqdm.write(f"  open [{opened}]: {t['component']} should be {t['expected']}, {moved}")
    agreeing, total = sum(b["agreeing"] for b in boxes), sum(b["total"] for b in boxes)
    held = [b["held_move_max"] for b in boxes if b["held_move_max"] is not None]
    summary = {
        "spec": f"total ({len(boxes)} box(es))",
        "agreeing": agreeing,
        "total": total,
        "held_move_max": max(held) if held else None,
        "unrealized": [u for b in boxes for u in b["unrealized"]],
    }
    if args.json:
        record = {"locks": args.locks, "with_robot": args.with_robot, "agreeing": agreeing, "total": total}
        print(f"wrote {write_json(Path(args.json), {**record, 'boxes': boxes, 'errors': errors})}")
    print(_box_line(summary) + (f"; {len(errors)} box(es) not built" if errors else ""))
    if errors:
        return 2
    return 1 if agreeing < total else 0


def _compiled(spec: PuzzleSpec, locks: str, with_robot: bool) -> tuple[mujoco.MjModel, dict[str, str]]:
    """The compiled model of ``spec`` (the box alone, or the whole scene) and each component's joint name."""
    if not with_robot:
        from puzzlebox.models.box_export import compile_box

        return compile_box(spec, locks)
    from puzzlebox.models.scene import SceneConfig, build_scene

    scene = build_scene(spec, SceneConfig(locks=locks))  # UnreachableBoxPose: a ModelsError
    return scene.compile(), {name: names.joint for name, names in scene.names.components.items()}


def _box_record(file: str, spec: PuzzleSpec, result: LockCheck, unrealized: list[tuple[LockRule, str]]) -> dict:
    """One box's check as JSON-ready data (moves are fractions of a part's travel)."""
    held = result.held_moves()
    return {
        "spec": spec.name,
        "file": str(file),
        "agreeing": result.agreeing,
        "total": len(result.transitions),
        "held_move_max": max(held) if held else None,
        "disagreements": [
            {
                "open": [c.name for k, c in enumerate(spec.components) if (t.state >> k) & 1],
                "component": t.component,
                "expected": "free" if t.expected_free else "held",
                "moved": t.moved,
            }
            for t in result.disagreements()
        ],
        "unrealized": [{**dataclasses.asdict(rule), "reason": reason} for rule, reason in unrealized],
    }


def _box_line(box: dict) -> str:
    held = box["held_move_max"]
    moved = "no part held" if held is None else f"held parts moved at most {100 * held:.1f} % of their travel"
    agree = f"{box['agreeing']}/{box['total']} transitions agree"
    return f"{box['spec']}: {agree}; {moved}; {len(box['unrealized'])} rule(s) without a mechanism"


def _mesh(args: argparse.Namespace) -> None:
    from puzzlebox.models.lock_features import layout_lock_features
    from puzzlebox.models.mesh_export import export_meshes  # MuJoCo and trimesh only when asked

    try:
        spec = load_spec(args.spec)
    except SpecError as err:
        fail(one_line(err))
    if spec.box is None:
        fail(f"{args.spec}: spec {spec.name!r} is a disassembly scene (no box); only puzzle boxes export as meshes")
    paths = export_meshes(spec, args.out)
    print(f"wrote {len(paths)} files in {args.out}: {', '.join(p.name for p in paths[:3])} and one STL per part")
    layout = layout_lock_features(spec)
    print(f"lock features: {len(layout.features)} shown, {len(layout.skipped)} without room on their locker")
    for skipped in layout.skipped:  # a lock the physics enforces but the model cannot show: say so
        print(f"  not shown: {skipped.locker} -> {skipped.locked}: {skipped.reason}")


def _validate(args: argparse.Namespace) -> int:
    invalid = 0
    for file in args.files:
        try:
            spec = load_spec(file)
        except SpecError as err:
            invalid += 1
            for problem in err.problems:
                print(f"{file}: {problem}")
            continue
        plan = LockTable.from_spec(spec).shortest_solution()
        print(f"{file}: valid ({len(spec.components)} components, shortest solution {len(plan or [])} actions)")
    if invalid:
        print(f"{invalid} of {len(args.files)} file(s) invalid", file=sys.stderr)
    return 1 if invalid else 0


def _dataset_flags(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--count", type=int, default=None, help="N specs, seeds S..S+N-1: --out is a directory")
    parser.add_argument("--workers", type=int, default=None, help="with --count: worker processes (default: cores)")
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="with --count: generate on Ray")


def _locks_flag(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--locks",
        choices=LOCK_MODES,
        default="contact",
        help="lock rules as mechanisms that block by contact (default) or as latches alone (no mechanism)",
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
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
    chain.add_argument("--out", required=True, help="output JSON file")
    chain.add_argument("--name", default=None, help="spec name (default: derived from kinds and seed)")
    chain.add_argument("--plot", action="store_true", help="also write a top-view PNG beside each JSON")
    chain.add_argument(
        "--anywhere",
        action="store_true",
        help="keep the box at the default pose even if the robot cannot reach every handle (symbolic only)",
    )
    _dataset_flags(chain)
    chain.set_defaults(run=_chain)

    rand = verbs.add_parser("random", help="a random solvable lock graph of N components")
    rand.add_argument("--components", type=int, required=True)
    rand.add_argument("--seed", type=int, required=True)
    rand.add_argument("--multi-locker", action="store_true", help="some components get two lockers")
    rand.add_argument(
        "--kinds",
        choices=("paper", "all"),
        default="paper",
        help="kinds drawn: the paper's door/slide/wheel (default) or every registered kind (models.kinds)",
    )
    rand.add_argument("--out", required=True, help="output JSON file")
    rand.add_argument("--name", default=None, help="spec name (default: derived from N and seed)")
    rand.add_argument("--plot", action="store_true", help="also write a top-view PNG beside each JSON")
    rand.add_argument(
        "--anywhere",
        action="store_true",
        help="keep the box at the default pose even if the robot cannot reach every handle (symbolic only)",
    )
    _dataset_flags(rand)
    rand.set_defaults(run=_random)

    scene = verbs.add_parser("mjcf", help="the MuJoCo scene of a spec: DIR/scene.xml (or DIR/box.xml) + assets")
    scene.add_argument("spec", help="puzzle spec file")
    scene.add_argument("--out", required=True, help="output directory")
    scene.add_argument("--box-only", action="store_true", help="the box alone, lid frame at the origin: DIR/box.xml")
    _locks_flag(scene)
    scene.set_defaults(run=_mjcf)

    check = verbs.add_parser("check-locks", help="does each box's model alone hold its lock rules? exit 1 if not")
    check.add_argument("specs", nargs="+", metavar="SPEC", help="puzzle spec files")
    check.add_argument("--with-robot", action="store_true", help="check the whole scene (table, robot, box)")
    _locks_flag(check)
    check.add_argument("--json", default=None, metavar="FILE", help="also write every box's result to FILE")
    check.set_defaults(run=_check_locks)

    mesh = verbs.add_parser(
        "mesh",
        help="the box as meshes: DIR/<name>.glb, .obj, .stl and one STL per part (shell, components, mechanisms)",
    )
    mesh.add_argument("spec", help="puzzle spec file")
    mesh.add_argument("--out", required=True, help="output directory")
    mesh.set_defaults(run=_mesh)

    validate = verbs.add_parser("validate", help="check spec files; exit 1 if any is invalid")
    validate.add_argument("files", nargs="+")
    validate.set_defaults(run=_validate)

    args = parser.parse_args(argv)
    if getattr(args, "count", None) is None and (getattr(args, "workers", None) or getattr(args, "ray", None)):
        fail("--workers and --ray go with --count (a dataset)")
    try:
        return args.run(args) or 0
    except ModelsError as err:
        fail(str(err))
    except OSError as err:
        fail(f"cannot write output: {err}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
