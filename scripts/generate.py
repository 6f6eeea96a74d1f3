"""Generate and validate puzzle specs.

    python scripts/generate.py paper --split {train,test,all} --out DIR     # DIR/<name>.json
    python scripts/generate.py chain --kinds door,slide,wheel --seed S --out FILE
    python scripts/generate.py random --components N --seed S [--multi-locker] [--kinds paper|all] --out FILE
    python scripts/generate.py random|chain ... --count N --out DIR [--workers K | --ray auto|ADDRESS]
    python scripts/generate.py validate FILE...     # exit 1 and one line per problem if any is invalid
    python scripts/generate.py mjcf SPEC --out DIR  # DIR/scene.xml + assets, loadable by mujoco
    python scripts/generate.py mesh SPEC --out DIR  # DIR/<name>.glb|.obj|.stl + <name>-<part>.stl

``mesh`` exports the box as the MuJoCo model has it (at start, every component closed): one part per
component plus ``box`` (the shell), in the lid frame (origin at the centre of the lid's top face, z up),
in metres; STL has no part names, hence one STL per part beside the merged one (``models.mesh_export``).

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
from pathlib import Path

from _cli import fail, one_line
from tqdm import tqdm

from models import LockTable, ModelsError, PuzzleSpec, SpecError, load_spec, save_spec
from models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random, paper_family
from models.kinds import family_named


def _write(spec: PuzzleSpec, path: Path, plot: bool) -> None:
    print(f"wrote {save_spec(spec, path)}  ({'-'.join(spec.kinds)})")
    if plot:
        from _spec_plot import plot_spec  # matplotlib only when asked

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
    from _dataset import spec_task, write_manifest, write_spec
    from _interrupt import StopRequests

    from learning.runner import RunnerError, make_executor

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
                    from _spec_plot import plot_spec

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


def _mjcf(args: argparse.Namespace) -> None:
    from models.scene import build_scene  # MuJoCo only when asked

    try:
        spec = load_spec(args.spec)
    except SpecError as err:
        fail(str(err))
    path = build_scene(spec).export(args.out)
    print(f"wrote {path} and its assets ({len(list(Path(args.out).iterdir())) - 1} files)")


def _mesh(args: argparse.Namespace) -> None:
    from models.lock_features import layout_lock_features
    from models.mesh_export import export_meshes  # MuJoCo and trimesh only when asked

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

    scene = verbs.add_parser("mjcf", help="the MuJoCo scene of a spec: DIR/scene.xml + assets")
    scene.add_argument("spec", help="puzzle spec file")
    scene.add_argument("--out", required=True, help="output directory")
    scene.set_defaults(run=_mjcf)

    mesh = verbs.add_parser("mesh", help="the box as meshes: DIR/<name>.glb, .obj, .stl and one STL per part")
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
