"""Resuming: `oceanmc run --resume` continues the partial results file at a run's output path.
partial_run says whether that file may be continued by the scene (CannotResume, one line, if
not); RunFile writes the run's results there as it goes (checkpoints) and at its end, each
combined with the partial run it continues, which is what a later --resume continues in turn."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .format import save_result
from .hdf5 import load_result
from .merge import MergeError, check_resumable, check_same_data_files, merge_results, \
    scene_difference
from .result import Result
from .simulation import PreparedRun


class CannotResume(ValueError):
    """A results file that --resume cannot continue; the message says why, in one line."""


def partial_run(out: Path, run: PreparedRun, config_path: Path) -> Result:
    """The partial results file at `out`, made by an earlier run of the scene of
    `config_path` (`run`, prepared from it) and not finished: the run continues its batches."""
    try:
        previous = load_result(out)
    except ValueError as exc:  # ResultsFileError: one line saying what is wrong
        raise CannotResume(f"{out}: {exc}") from None
    if not previous.attrs.get("partial", False):
        raise CannotResume(f"{out} is already complete ({previous.attrs['batches']} batches)")
    try:
        check_resumable(previous)
    except MergeError as exc:
        raise CannotResume(f"{out}: {exc}") from None
    done = int(previous.attrs["first_batch"]) + int(previous.attrs["batches"])
    if done >= run.config.batches:
        raise CannotResume(f"{out} is marked partial but holds batches up to {done - 1} of "
                           f"{config_path}'s {run.config.batches}: nothing to continue")
    differs = scene_difference(previous.config_yaml, run.scene_yaml)
    if differs and not scene_difference(previous.config_yaml, run.scene_yaml, "photons", "seed"):
        # only what `oceanmc run` takes on its command line: say which options to give again
        import yaml
        stored = yaml.safe_load(previous.config_yaml)
        keys = [key for key in ("photons", "seed") if stored.get(key) != getattr(run.config, key)]
        raise CannotResume(
            f"{out} was run with {', '.join(f'{key} = {stored[key]}' for key in keys)} (the "
            f"scene's, or given by --{' / --'.join(keys)}), {config_path} gives "
            f"{', '.join(f'{getattr(run.config, key)}' for key in keys)}: give "
            f"{' '.join(f'--{key} {stored[key]}' for key in keys)} to continue it")
    if differs:
        raise CannotResume(f"{out} was made from a different scene than {config_path} "
                           f"({differs}; compare with `oceanmc show --config`)")
    try:
        check_same_data_files(previous.attrs, {"data_files_sha256": run.data_hashes},
                              str(config_path))
    except MergeError as exc:
        raise CannotResume(str(exc)) from None
    return previous


class RunFile:
    """A run's results file: written at each checkpoint and at the end, each time with the
    batches of the partial run it continues (`previous`, from partial_run) before its own. The
    first placement refuses to replace a file another run made meanwhile (unless overwrite, or
    when continuing that file); the ones that follow replace this run's own file."""

    def __init__(self, path: Path, previous: Result | None, overwrite: bool) -> None:
        self.path, self.previous = path, previous
        self.replace = overwrite or previous is not None
        self.checkpointed = False

    @property
    def first_batch(self) -> int:
        """The run's first batch: the one after the whole batches of the run it continues."""
        if self.previous is None:
            return 0
        return int(self.previous.attrs.get("first_batch", 0)) + \
            int(self.previous.attrs["batches"])

    @property
    def resume_state(self) -> dict[str, np.ndarray] | None:
        """The unfinished batches of the run it continues, to be continued where they stopped."""
        return None if self.previous is None else self.previous.resume_state

    def combined(self, result: Result) -> Result:
        """The run's result after the batches of the run it continues (MergeError if they do
        not follow one another)."""
        return result if self.previous is None else \
            merge_results([self.previous, result], resume=True)

    def checkpoint(self, partial: Result) -> None:
        save_result(self.combined(partial), self.path, self.replace)
        self.replace = self.checkpointed = True

    def save(self, result: Result) -> None:
        """The run's end (a result already combined). Written by save_result, not Result.save,
        whose refusal of an existing file comes before writing: a file another run made
        meanwhile would have lost this run's results with a FileExistsError (a user's review,
        two runs to one new file); place_atomically keeps them beside it instead
        (ResultsSavedElsewhere)."""
        save_result(result, self.path, self.replace)

    def discard(self) -> None:
        """Removes the file this run's checkpoints made, when its end is refused: a continued
        file keeps its last checkpoint (finite, as every checkpoint written)."""
        if self.checkpointed and self.previous is None:
            self.path.unlink(missing_ok=True)
