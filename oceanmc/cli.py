"""The `oceanmc` command: run scenes, sweep them, validate the physics, show and plot results
files.

Exit status: 0 success, 1 a failed validation or a run that could not finish, 2 bad input (a
config, a path, an option), 130 interrupted.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import signal
import stat
import sys
import tempfile
import warnings
from pathlib import Path

from . import __version__


class UsageError(Exception):
    """Bad command-line input; the message says what and why."""


# what -o takes as a results file's name (HDF5; h5netcdf reads .nc as well)
RESULT_SUFFIXES = (".h5", ".hdf5", ".nc")


def _names_a_folder(out: str) -> bool:
    return out.endswith(("/", os.sep))


def _existing(path: Path) -> str:
    """'folder', 'file' (a regular one), 'other' (a device such as /dev/null, a FIFO, a socket)
    or '' (nothing there, or a name the system cannot take: _check_writable says why)."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):   # ValueError: a NUL byte
        return ""
    return "folder" if stat.S_ISDIR(mode) else "file" if stat.S_ISREG(mode) else "other"


def _results_file(out: str, option: str = "-o", suffixes: tuple[str, ...] = RESULT_SUFFIXES,
                  what: str = "a results file", allowed: str | None = None) -> Path:
    """The file -o names where the command writes one file: a name ending in one of suffixes,
    not a folder, not a device or a FIFO (they would be replaced, or written into a name
    beside them). allowed: what the refusals say the option takes (default: such a name)."""
    target = Path(out)
    others = f" (or {', '.join(suffixes[1:])})" if len(suffixes) > 1 else ""
    allowed = allowed or f"{what} name ending in {suffixes[0]}{others}"
    if out == "":   # Path('') is the current folder
        raise UsageError(f"{option} '': an empty name; {option} takes {allowed}")
    if _names_a_folder(out) or _existing(target) == "folder":
        raise UsageError(f"{option} {out}: a folder; {option} takes {allowed}")
    if _existing(target) == "other":
        raise UsageError(f"{option} {out}: not a regular file (a device, a FIFO or a socket); "
                         f"{option} takes {allowed}")
    if target.suffix.lower() not in suffixes:
        raise UsageError(f"{option} {out}: {option} takes {allowed}")
    return target


def _outputs(configs: list[Path], out: str | None) -> list[Path]:
    """One results file per config: -o FILE.h5 (.hdf5, .nc) for a single config, and -o NAME
    without a suffix (not an existing folder) the file NAME.h5; -o DIR (an existing folder, a
    name ending in '/', or, for several configs, a name without a suffix, made if need be)
    gets each file named after its config; else results/<config name>.h5. Any other -o (an
    empty name, another suffix such as .yaml, a device such as /dev/null) is refused by
    _results_file."""
    if out is None:
        return [Path("results") / f"{c.stem}.h5" for c in configs]
    target = Path(out)
    kind = _existing(target) if out else ""
    several = f"-o {out}: several configs need a folder for -o, not a file name"
    if kind == "folder" or _names_a_folder(out):
        return [target / f"{c.stem}.h5" for c in configs]
    if out and not target.suffix and kind != "other":
        if len(configs) == 1:
            return [target.with_name(target.name + ".h5")]   # `-o name` means the file name.h5
        if kind == "":
            return [target / f"{c.stem}.h5" for c in configs]   # several: the folder name/
        raise UsageError(several)   # an existing file
    target = _results_file(out, allowed="a results file name ending in .h5 (or .hdf5, .nc) or "
                           "without a suffix (NAME.h5; one config) or a folder (an existing one, "
                           "or a name ending in /)")
    if len(configs) > 1:
        raise UsageError(several)
    return [target]


def _check_writable(path: Path, overwrite: bool, need_bytes: int = 0,
                    resumable: bool = True) -> None:
    """Fails before any photon is traced if the results file cannot be written (resumable:
    the command has --resume, which the message then names)."""
    if "\0" in str(path):   # no file system takes one; Path.exists() just says False
        raise UsageError(f"{str(path)!r}: a file name cannot hold a NUL byte")
    if path.exists() and path.is_dir():
        raise UsageError(f"{path} is a folder, not a results file")
    if path.exists() and not overwrite:
        raise UsageError(f"{path} exists; pass --overwrite to replace it"
                         + (" (or --resume to continue a partial run)" if resumable else ""))
    folder = path.parent if str(path.parent) else Path(".")
    # (mkdir alone says "File exists" of a folder path through a file, and an unwritable
    # system folder such as /proc may answer "No such file or directory")
    for above in (folder, *folder.parents):
        if above.is_symlink() and not above.exists():   # (exists() follows the link)
            raise UsageError(f"cannot write results to {path}: {above} is a broken symbolic "
                             "link")
        if above.exists():
            if not above.is_dir():
                raise UsageError(f"cannot write results to {path}: {above} is a file, not a "
                                 "folder")
            break
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"cannot make the folder {folder} for the results: "
                         f"{exc.strerror or exc}") from None
    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".oceanmc-write-test-"):
            pass
    except OSError as exc:
        raise UsageError(f"cannot write results to {folder}: a new file there cannot be made "
                         f"({exc.strerror or exc})") from None
    free = shutil.disk_usage(folder).free
    if free < 2 * need_bytes:
        raise UsageError(f"not enough disk space in {folder}: about {need_bytes / 1e6:.1f} MB "
                         f"needed, {free / 1e6:.1f} MB free")


def _file_size_estimate(config) -> int:
    """Bytes of a results file, roughly: every value is stored per batch, mean and stderr."""
    n_theta = len(config.tallies.theta_edges) - 1
    quad = n_theta * config.tallies.phi_bands if config.tallies.radiance else 0
    per_batch = len(config.tallies.depths_m) * (6 + quad) + 3 * quad + \
        len(config.water.layers) + 20
    return 8 * per_batch * (config.batches + 2)


class StopRequest:
    """The first SIGINT or SIGTERM asks the run to stop (the kernel returns within a fraction of
    a second, simulation.CALL_SECONDS) and write what it has; the default handlers come back, so
    a second signal ends the process at once (the atomic write means no results file is ever
    left half written). Installed whatever the signals' handlers were: a command started in the
    background by a script inherits SIGINT as ignored, and `kill -INT` must still stop it."""

    def __init__(self, doing: str = "stopping and writing the photons done so far") -> None:
        self.requested = False
        self.signal_name = ""
        self.doing = doing

    def __call__(self, signum, frame) -> None:
        self.requested = True
        self.signal_name = signal.Signals(signum).name
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        print(f"\noceanmc: {self.signal_name}: {self.doing}; press Ctrl-C again to quit at "
              "once", file=sys.stderr, flush=True)

    def install(self) -> None:
        signal.signal(signal.SIGINT, self)
        signal.signal(signal.SIGTERM, self)


def _ready_or_exit(scene_files: list[Path], configs: list) -> None:
    """Compiles the photon loop with the parts the scenes will use (kernel/variants.py), or
    loads it from the cache (on a cold start the compiling child packs scene_files meanwhile:
    run/compiling.py); the first SIGINT or SIGTERM while it compiles ends the process at once
    (the compilation goes on in its own thread inside LLVM), with exit status 130 and nothing
    written. The signals' handlers are as before afterwards."""
    from .kernel.variants import union
    from .run.compiling import CompileInterrupted, ready
    from .scene import predicted_variant
    stop = StopRequest("stopping")
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    stop.install()
    try:
        ready(union(map(predicted_variant, configs)), lambda: stop.requested, scene_files)
    except CompileInterrupted as exc:
        print(f"oceanmc: stopped by {stop.signal_name} {exc}; "
              "nothing was traced and no file was written", file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(130)
    for signum, handler in zip((signal.SIGINT, signal.SIGTERM), before):
        if handler is not None:   # None: not installed from Python, nothing to restore
            signal.signal(signum, handler)


def cmd_run(args: argparse.Namespace) -> int:
    from .config import ConfigError, load_config
    from .run.merge import MergeError
    from .run.resume import CannotResume, RunFile, partial_run
    from .run.simulation import NonFiniteResult, prepare, simulate
    from .run.summary import format_summary

    if args.resume and args.overwrite:   # (together it started over, silently: a review)
        raise UsageError("--resume and --overwrite together: --resume continues a partial "
                         "file, --overwrite replaces it with a new run; give one of them")
    configs = [Path(c) for c in args.configs]
    outputs = _outputs(configs, args.output)
    if len(set(outputs)) != len(outputs):
        twice = next(o for o in outputs if outputs.count(o) > 1)
        same = " and ".join(str(c) for c, o in zip(configs, outputs) if o == twice)
        raise UsageError(f"{same} would both write {twice}; give them different names or run them "
                         "separately with -o")
    overrides = {"photons": args.photons, "seed": args.seed}

    def config_error(path: Path, exc: ConfigError) -> int:
        print(one_line(f"oceanmc: config error: {path}: {exc}" if str(path) not in str(exc)
                       else f"oceanmc: config error: {exc}"), file=sys.stderr)
        return 2

    # every config is checked, and each bad one named, before any is run
    loaded, bad = [], 0
    for path in configs:
        try:
            loaded.append(load_config(path, overrides))
        except ConfigError as exc:
            bad = config_error(path, exc)
    if bad:
        return bad
    # the photon loop is compiled (or loaded) before any scene is packed: the packers call
    # kernel functions, which the compiling child process then compiles off the critical path,
    # and it packs the scenes while trace_batch compiles (run/compiling.py; packing first
    # compiled them here, 2-3 s of a cold start)
    _ready_or_exit(configs, loaded)
    runs = []
    for path, config in zip(configs, loaded):
        try:
            # reads its data files: every scene is checked before any runs
            runs.append(prepare(config))
        except ConfigError as exc:
            bad = config_error(path, exc)
    if bad:   # (before any results folder is made)
        return bad
    scenes = []
    for path, out, run in zip(configs, outputs, runs):
        _check_writable(out, args.overwrite or (args.resume and out.exists()),
                        _file_size_estimate(run.config))
        previous = None
        if args.resume and out.exists():
            try:
                previous = partial_run(out, run, path)
            except CannotResume as exc:
                raise UsageError(f"--resume: {exc}") from None
        elif args.resume:   # (a resubmitted job whose first try never wrote: not an error)
            print(one_line(f"oceanmc: --resume: no file at {out} to continue; running {path} "
                           "from the start"), file=sys.stderr, flush=True)
        scenes.append((path, run, RunFile(out, previous, args.overwrite)))

    stop = StopRequest()
    stop.install()
    for path, run, output in scenes:
        try:
            result = output.combined(simulate(
                run, threads=args.threads, progress=not args.quiet,
                first_batch=output.first_batch, should_stop=lambda: stop.requested,
                on_checkpoint=output.checkpoint, checkpoint_every_s=args.checkpoint_every,
                resume_state=output.resume_state))
        except MergeError as exc:
            raise UsageError(f"--resume: {exc}") from None
        except NonFiniteResult as exc:
            # a file this run's checkpoints made before the fault showed is not left as if the
            # scene had run well
            output.discard()
            print(one_line(f"oceanmc: error: {path}: {exc}"), file=sys.stderr)
            return 3
        result.attrs["config_file"] = str(path)
        output.save(result)
        print(format_summary(result))
        print(f"  wrote {output.path}")
        if result.attrs.get("partial"):   # the summary's PARTIAL line says how much is whole
            unfinished = result.resume_state
            n = 0 if unfinished is None else len(unfinished["batch"])
            begun = f"{n} more batch{'es' if n > 1 else ''} begun, kept to be continued; " \
                if n else ""
            print(f"  {begun}continue with: oceanmc run {path} -o {output.path} --resume"
                  + "".join(f" --{key} {value}" for key, value in overrides.items()
                            if value is not None))
        print()
        if stop.requested:
            print(f"oceanmc: stopped by {stop.signal_name}", file=sys.stderr)
            return 130
    return 0


def cmd_merge(args: argparse.Namespace) -> int:
    from .config.loading import file_problem
    from .run.hdf5 import load_result
    from .run.merge import MergeError, merge_results
    from .run.summary import format_summary

    out = _results_file(args.output)
    parts = []
    for name in args.files:
        path = Path(name)
        problem = file_problem(path)
        if problem:
            raise UsageError(f"{path}: {problem}")
        try:
            parts.append(load_result(path))
        except ValueError as exc:  # ResultsFileError: one line saying what is wrong
            raise UsageError(f"{path}: {exc}") from None
    # the merged file holds every input's batches: about their files' sizes together (on a
    # full disk h5py's write failed in C, 1300 lines of tracebacks and a segfault: a review)
    _check_writable(out, args.overwrite, sum(Path(name).stat().st_size for name in args.files),
                    resumable=False)
    try:
        merged = merge_results(parts)
    except MergeError as exc:
        raise UsageError(f"cannot merge: {exc}") from None
    merged.save(out, overwrite=args.overwrite)
    print(format_summary(merged))
    print(f"  wrote {out}")
    return 0


def cmd_show(args: argparse.Namespace) -> int:
    from .config.loading import file_problem
    from .run.derived import format_derived
    from .run.hdf5 import load_result
    from .run.summary import format_iops, format_summary

    path = Path(args.file)
    problem = file_problem(path)
    if problem:
        raise UsageError(f"{path}: {problem}")
    try:
        result = load_result(path)
    except ValueError as exc:  # ResultsFileError: one line saying what is wrong
        raise UsageError(f"{path}: {exc}") from None
    print(format_summary(result))
    print(format_derived(result))
    if args.iops:
        print(format_iops(result))
    if args.config:
        print(result.config_yaml)
    return 0


def cmd_plot(args: argparse.Namespace) -> int:
    from .plot.results import PlotInputError, plot_result

    try:
        written = plot_result(args.file, args.output, depth=args.depth, wavelength=args.wavelength)
    except PlotInputError as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        where = f"-o {args.output}" if args.output is not None else \
            f"{Path(args.file).parent or Path('.')} (beside the results file; -o names another)"
        raise UsageError(f"{where}: cannot write the figures there "
                         f"({exc.strerror or exc})") from None
    for name, path in written.items():
        if isinstance(path, str):   # why it was not drawn
            print(f"oceanmc: plot: {args.file} {path}; no {name} figure", file=sys.stderr)
        else:
            print(f"wrote {path}")
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    import numpy as np

    from .config.loading import file_problem
    from .run.compiling import CompileInterrupted
    from .sweeps import FailedPoints, OutputExists, SweepError, sweep

    source = Path(args.sweep)
    out = _results_file(args.output, suffixes=(".nc",), what="a NetCDF file") \
        if args.output is not None else Path("results") / f"{source.stem}.nc"
    problem = file_problem(source)   # a FIFO or a device is "not a regular file", not missing
    if problem:
        raise UsageError(f"{source}: {problem}")
    _check_writable(out, overwrite=True)   # what the sweep may replace: sweep() judges it
    # the same signals, the same way, as `oceanmc run`: SIGTERM (a batch scheduler's) and a
    # SIGINT inherited as ignored (a background job of a script) stop it as Ctrl-C does
    stop = StopRequest("stopping: cancelling the points not finished, then writing the dataset "
                       "with those done and closing the workers")
    stop.install()
    try:
        with warnings.catch_warnings():   # the failed points are listed below, exit 1
            warnings.simplefilter("ignore", FailedPoints)
            lut = sweep(source, out, workers=args.workers, scheduler=args.scheduler,
                        threads=args.threads, batch_groups=args.batch_groups,
                        workers_write=True if args.workers_write else None,
                        progress=not args.quiet,
                        log=lambda text: print(f"oceanmc: sweep: {text}", file=sys.stderr,
                                               flush=True),
                        overwrite=args.overwrite, should_stop=lambda: stop.requested)
    except OutputExists as exc:
        raise UsageError(str(exc)) from None
    except SweepError as exc:
        print(one_line(f"oceanmc: config error: {exc}"), file=sys.stderr)
        return 2
    except CompileInterrupted as exc:
        # the compilation goes on in its own thread inside LLVM; leave at once (as cmd_run)
        print(f"oceanmc: stopped by {stop.signal_name} {exc}; no "
              "point ran and no dataset was written", file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(130)
    except KeyboardInterrupt:   # a KeyboardInterrupt raised by other means than the signal
        print(f"oceanmc: sweep interrupted: wrote {out} with the points done so far (status "
              f"'pending' for the others); the same command finishes it", file=sys.stderr)
        return 130
    a = lut.attrs
    if stop.requested:
        print(f"oceanmc: sweep interrupted: wrote {out} with the points done so far "
              f"({a['points_done']} of {a['points']}; status 'pending' for the others; stopped "
              f"by {stop.signal_name}); the same command finishes it", file=sys.stderr)
        return 130
    print(f"{a['points_done']} of {a['points']} points done, {a['points_failed']} failed; "
          f"wrote {out} (finished points are kept in {out.with_suffix('.points')}/)")
    failed = lut["status"].values == "failed"
    for at in np.argwhere(failed):   # (a sweep with no axes is one point: 0-d arrays)
        index = tuple(at)
        where = ", ".join(f"{dim} = {lut[dim].values[i]}" for dim, i in zip(lut.attrs["axes"]
                                                                        .split(","), index))
        print(f"  failed{f' ({where})' if where else ''}: {lut['error'].values[index]}")
    return 1 if a["points_failed"] else 0


def cmd_validate(args: argparse.Namespace) -> int:
    from . import validation

    return validation.main(Path(args.output), quick=args.quick)


def cmd_bench(args: argparse.Namespace) -> int:
    from . import bench
    from .run.compiling import OWN_VARIANT_ENV

    if not args.quick:
        # each scene on the photon loop's variant with its own parts, whatever the cache holds
        # (run/compiling.py); the quick smoke test takes what is at hand instead of compiling
        # a variant per scene
        os.environ[OWN_VARIANT_ENV] = "1"

    if args.spectral:
        from .bench import spectral
        return spectral.main(Path(args.output), args.quick)

    if args.sweep:
        from .bench import sweep
        return sweep.main(Path(args.output), quick=args.quick)

    if args.surface:
        from .bench import surface
        return surface.main(Path(args.output), Path(args.configs), args.quick)

    if args.real_scenes:
        from .bench import real_scenes
        return real_scenes.main(Path(args.output), args.quick)

    if args.inelastic:
        from .bench import inelastic
        return inelastic.main(Path(args.output), args.quick)

    if args.deep:
        from .bench import deep
        return deep.main(Path(args.output), args.quick)

    configs = Path(args.configs)
    if not (configs / "bare_walk.yaml").is_file():
        raise UsageError(f"--configs {configs}: no bare_walk.yaml there (run from the "
                         "repository root, or point --configs at its configs/ folder)")
    bare_walk = Path(args.bare_walk) if args.bare_walk else None
    if bare_walk is None:
        for candidate in (Path("../shared/bench/bare_walk.py"),
                          Path(__file__).resolve().parents[2] / "shared/bench/bare_walk.py"):
            if candidate.is_file():
                bare_walk = candidate
                break
    elif not bare_walk.is_file():
        raise UsageError(f"--bare-walk {bare_walk}: no such file")
    if bare_walk is None:
        print("oceanmc: bench: shared/bench/bare_walk.py not found; the speed ceiling is "
              "reported without it (--bare-walk PATH)", file=sys.stderr)
    return bench.main(Path(args.output), configs, bare_walk, quick=args.quick,
                      speed_only=args.speed)


class OneLineParser(argparse.ArgumentParser):
    """Bad options in one line (exit 2), pointing at --help rather than printing the usage."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="oceanmc",
        description="Monte Carlo radiative transfer for natural waters: layered water, flat "
                    "Fresnel surface, BRDF bottom, sun and sky.")
    parser.add_argument("--version", action="version", version=f"oceanmc {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    run = sub.add_parser("run", help="run one or more YAML scenes, write one HDF5 file each")
    run.add_argument("configs", nargs="+", metavar="CONFIG.yaml")
    run.add_argument("-o", "--output", metavar="OUT",
                     help="results file OUT.h5 (one config; OUT without a suffix means "
                          "OUT.h5), or a folder for <name>.h5 files: an existing one, or a "
                          "name ending in / (or, for several configs, without a suffix) "
                          "(default: results/<name>.h5)")
    run.add_argument("--photons", type=_photon_count,
                     help="photon packets, at most 1e13 (overrides config)")
    run.add_argument("--seed", type=_non_negative_int, help="random seed (overrides config)")
    run.add_argument("--threads", type=_positive_int,
                     help="threads (default: all cores); results do not depend on it")
    run.add_argument("--overwrite", action="store_true", help="replace existing results files")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    run.add_argument("--resume", action="store_true",
                     help="continue the partial results file at the output path")
    run.add_argument("--checkpoint-every", type=_seconds, default=60.0, metavar="SECONDS",
                     help="write the batches done so far this often (default 60 s; 0: at "
                          "every check, about twice a second)")
    run.set_defaults(func=cmd_run)

    merge = sub.add_parser("merge", help="combine independent runs of one scene (other seeds)")
    merge.add_argument("files", nargs="+", metavar="RESULT.h5")
    merge.add_argument("-o", "--output", required=True, metavar="OUT.h5")
    merge.add_argument("--overwrite", action="store_true", help="replace an existing OUT.h5")
    merge.set_defaults(func=cmd_merge)

    sweep = sub.add_parser("sweep", help="a look-up table: one scene over axes of its keys, "
                                         "on Dask; one NetCDF dataset")
    sweep.add_argument("sweep", metavar="SWEEP.yaml",
                       help="base scene and axes (README: Sweeps)")
    sweep.add_argument("-o", "--output", metavar="LUT.nc",
                       help="the dataset (default: results/<sweep name>.nc)")
    where = sweep.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_positive_int,
                       help="worker processes of a local Dask cluster (default: one per core)")
    where.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                       help="an existing Dask scheduler to run the points on")
    sweep.add_argument("--threads", type=_positive_int,
                       help="threads per point (default: the cores shared among local workers; "
                            "with --scheduler, the worker's cores)")
    sweep.add_argument("--batch-groups", type=_positive_int, metavar="N",
                       help="spread each point's batches over N tasks (merged exactly; "
                            "overrides the sweep file's batch_groups)")
    sweep.add_argument("--workers-write", action="store_true",
                       help="with --scheduler: the workers see the output folder (a shared file "
                            "system) and write each point's file themselves")
    sweep.add_argument("--overwrite", action="store_true",
                       help="replace an output file that is not this sweep's dataset (another "
                            "sweep's, or not a sweep dataset); a rerun of the same sweep, or "
                            "one with values added to its axes, needs no --overwrite")
    sweep.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    sweep.set_defaults(func=cmd_sweep)

    validate = sub.add_parser("validate", help="run the validation suite and write its report")
    validate.add_argument("-o", "--output", default="validation", metavar="DIR",
                          help="report folder (default: validation)")
    validate.add_argument("--quick", action="store_true",
                          help="fewer photons: a fast check, looser standard errors")
    validate.set_defaults(func=cmd_validate)

    bench = sub.add_parser("bench", help="run time against error; speed against the bare walk")
    bench.add_argument("-o", "--output", default="benchmarks", metavar="DIR",
                       help="report folder (default: benchmarks)")
    bench.add_argument("--quick", action="store_true", help="small counts: a smoke test")
    bench.add_argument("--speed", action="store_true",
                       help="only the speed ceiling, the feature costs and the start-up rows "
                            "(DIR/speed.md): what a change to the kernel reports")
    bench.add_argument("--spectral", action="store_true",
                       help="only the spectral section (one history against 31 runs): "
                            "DIR/spectral.md")
    bench.add_argument("--surface", action="store_true",
                       help="only the rough-sea section (DIR/surface.md): photons/s and FOM "
                            "of Rrs with the Cox-Munk surface against the flat one")
    bench.add_argument("--real-scenes", action="store_true",
                       help="only the real-scenes section (DIR/real_scenes.md): 31-band Rrs "
                            "of windy Case-1 waters by the defaults, time to 1%% per band")
    bench.add_argument("--inelastic", action="store_true",
                       help="only the inelastic section (DIR/inelastic.md): what Raman "
                            "scattering and chlorophyll fluorescence cost in clear deep water, "
                            "and their parts' time to 1%%")
    bench.add_argument("--deep", action="store_true",
                       help="only the deep-light section (DIR/deep.md): depth splitting on a "
                            "stratified column, time to 1%% per depth with and without")
    bench.add_argument("--sweep", action="store_true",
                       help="only the sweep benchmark (DIR/sweep.md): a 100-point LUT on 1 "
                            "and 2 Dask workers against a plain loop")
    bench.add_argument("--configs", default="configs", metavar="DIR",
                       help="folder with the benchmark scenes (default: configs)")
    bench.add_argument("--bare-walk", metavar="PATH",
                       help="the speed-ceiling script (default: ../shared/bench/bare_walk.py)")
    bench.set_defaults(func=cmd_bench)

    show = sub.add_parser("show", help="print the summary of a results file")
    show.add_argument("file", metavar="RESULT.h5")
    show.add_argument("--iops", action="store_true",
                      help="also print the IOPs the run used, layer by layer")
    show.add_argument("--config", action="store_true", help="also print the stored scene")
    show.set_defaults(func=cmd_show)

    plot = sub.add_parser("plot", help="draw a results file's Rrs spectrum, irradiance profiles "
                                       "and radiance distribution to PNG")
    plot.add_argument("file", metavar="RESULT.h5")
    plot.add_argument("-o", "--output", metavar="DIR|PREFIX",
                      help="folder, or file prefix for _rrs.png, _profiles.png, _radiance.png, "
                           "_kd_r.png "
                           "(default: RESULT without .h5)")
    plot.add_argument("--depth", type=float, metavar="Z",
                      help="tallied depth (m) of the radiance plot (default: 0, just below)")
    plot.add_argument("--wavelength", type=float, metavar="NM",
                      help="the profiles and the radiance at this wavelength only (default: "
                           "a few across the spectrum; the middle one for the radiance); the "
                           "Rrs and K, R spectra stay whole")
    plot.set_defaults(func=cmd_plot)
    return parser


def _positive_int(text: str) -> int:
    """A positive integer, 1e7 as well; 1.5e0 is refused (int(float()) made it 1)."""
    try:
        if "e" in text.lower():
            number = float(text)
            if not number.is_integer():   # 1.5e0, and 1e400 (inf)
                raise argparse.ArgumentTypeError(
                    f"expected a positive integer, got {text!r}"
                    + (f", which is {number:g}" if math.isfinite(number) else ""))
            value = int(number)
        else:
            value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def _photon_count(text: str) -> int:
    """--photons: a positive integer (1e7 as well) of at most the largest count a scene takes
    (config.scene.MAX_PHOTONS), refused in readable digits: int('1e99') has 100."""
    # (here: --help does not import the schema)
    from .config.scene import MAX_PHOTONS, readable_count

    try:
        number = float(text)   # 1e400 and a 400-digit integer: inf
    except ValueError:
        number = math.nan
    if number > MAX_PHOTONS:
        shown = repr(text) if len(text) <= 24 else readable_count(text)
        raise argparse.ArgumentTypeError(f"{shown} is more than {MAX_PHOTONS:.0e} photons; "
                                         f"allowed: 1 .. {MAX_PHOTONS:.0e}")
    return _positive_int(text)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0.0:
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds >= 0, got "
                                         f"{text!r}")
    return value


def _non_negative_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def one_line(text: str) -> str:
    """An error message as one line: a character that is not printable (a line break in a file
    name given to -o, say) written as its escape, as repr() writes it."""
    return text if text.isprintable() else "".join(
        c if c.isprintable() else repr(c)[1:-1] for c in text)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.func in (cmd_run, cmd_sweep) and signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        # a job a script started in the background inherits SIGINT as ignored; StopRequest
        # takes it over once the run begins, and before that (reading the scenes, building
        # their tables) `kill -INT` was dropped and the run went on to exit 0 (a user's
        # review): from here it interrupts, as in the foreground (exit 130, no file)
        signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        return args.func(args)
    except UsageError as exc:
        print(one_line(f"oceanmc: error: {exc}"), file=sys.stderr)
        return 2
    except BrokenPipeError:   # before OSError, its base: `oceanmc show x.h5 | head` is fine
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    except OSError as exc:
        if not hasattr(exc, "kept"):  # run.placement.ResultsSavedElsewhere
            raise
        print(one_line(f"oceanmc: error: {exc}"), file=sys.stderr)
        return 1 if "no space" in exc.reason else 2
    except KeyboardInterrupt:
        print("oceanmc: interrupted; no partial results file was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
