"""`oceanmc.run.results`, the names users, the plots and the tests import from here (README:
Migration), from the modules that define them: the model (result.py), merging (merge.py) and
the printed summary (summary.py)."""
from .merge import MergeError, merge_results
from .result import Quantity, Result
from .summary import (PART_LABELS, RELIABLE_BATCHES, format_summary, lowest_requested,
                      wavelength_ranges)

__all__ = ["MergeError", "PART_LABELS", "Quantity", "RELIABLE_BATCHES", "Result",
           "format_summary", "lowest_requested", "merge_results", "wavelength_ranges"]
