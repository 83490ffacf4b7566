"""The printed tables of `oceanmc run` and `oceanmc show`: a spectral table's cells and its
blocks of columns, shared by the run's summary (summary.py) and the derived quantities
(derived.py)."""

# the printed summary fits a terminal this wide: a spectral table's nm column (8 characters)
# and SPECTRAL_BLOCK columns of 16 (a value, its relative standard error)
SUMMARY_WIDTH = 100
SPECTRAL_BLOCK = (SUMMARY_WIDTH - 8) // 16


def value_cell(value: float, err: float) -> str:
    """A spectral table's cell of 15 characters: the value and its relative standard error in %
    (0.0% for a value of 0)."""
    rel = abs(err / value) if value != 0.0 else 0.0
    return f"{value:>9.4g} {rel:>5.1%}"


def spectral_blocks(wavelengths, headings: list[str], cells: list[list[str]],
                    groups: tuple[range, ...]) -> list[str]:
    """A spectral table's lines, one row per wavelength: column c (heading headings[c], its
    cell at wavelength k cells[c][k]) in blocks of at most SPECTRAL_BLOCK columns after the nm
    column, so that a line fits a terminal of SUMMARY_WIDTH characters; each group of columns
    (a range) starts a block of its own, and an empty line separates the blocks. A heading
    wider than a cell widens its column."""
    blocks = [range(start, min(start + SPECTRAL_BLOCK, group.stop))
              for group in groups for start in range(group.start, group.stop, SPECTRAL_BLOCK)]
    lines = []
    for b, block in enumerate(blocks):
        if b:
            lines.append("")
        width = {c: max(15, len(headings[c])) for c in block}
        lines.append(f"  {'nm':>6}" + "".join(f" {headings[c]:>{width[c]}}" for c in block))
        lines += [f"  {wavelength:>6g}" + "".join(f" {cells[c][k]:>{width[c]}}" for c in block)
                  for k, wavelength in enumerate(wavelengths)]
    return lines
