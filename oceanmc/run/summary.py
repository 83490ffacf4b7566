"""The printed summary of a Result (`oceanmc run`, `merge`, `show`): the headline quantities
with their standard errors, one row each for a monochromatic run and a table by wavelength for a
spectral one, with inelastic light its parts of Rrs nadir, and what the estimators, the
processes and the illumination were."""
from __future__ import annotations

import json
import textwrap

import numpy as np

from .derivation import budget_terms
from .result import Result
from .text_table import SUMMARY_WIDTH, spectral_blocks, value_cell


def nadir_estimate(result: Result) -> str:
    """How Lu, air/Lw_nadir and air/Rrs_nadir were estimated: 'local' (the polar cap's local,
    next-event estimate; with radiance quads the crossing estimates are beside them as
    *_crossing) or 'crossing' (the attribute Lu_method says which)."""
    method = str(result.attrs.get("Lu_method", ""))
    local = "local (next-event)" in method if method else "air/Rrs_nadir_crossing" in result
    return "local" if local else "crossing"


def direction_label(result: Result, k: int) -> str:
    """`180,0`: the exact direction k of local_directions_deg (theta, phi of travel, deg)."""
    return f"{result.coords['direction_theta'][k]:g},{result.coords['direction_phi'][k]:g}"


def local_directions(result: Result) -> range:
    """The indices of the exact directions with local estimates in air (none: empty)."""
    return range(len(result.coords.get("direction_theta", ())) if "air/Rrs_local" in result
                 else 0)


def summary_rows(result: Result) -> list[tuple[str, str, float, float]]:
    """(label, units, value, standard error) for the headline quantities of a run; the nadir
    quantities name their estimator (local or crossing), and each exact direction of
    local_directions_deg has its Rrs row."""
    rows = []
    how = f"({nadir_estimate(result)})"

    def row(label, name, units, index=None):
        if name not in result:
            return
        if "nm-1" in result.quantities[name].units:   # a spectrum model's (SPECTRL2)
            units = units.replace("W/m2", "W/m2/nm")
        value, err = result[name], result.stderr(name)
        if index is not None:
            value, err = value[index], err[index]
        rows.append((label, units, float(value), float(err)))

    row("Ed(0+)", "air/Ed", "W/m2")
    row("Eu(0+)", "air/Eu", "W/m2")
    row("Lu(0+) nadir (crossing)", "air/Lu", "W/m2/sr")
    row(f"Lw nadir {how}", "air/Lw_nadir", "W/m2/sr")
    row(f"Rrs nadir {how}", "air/Rrs_nadir", "1/sr")
    for k in local_directions(result):
        row(f"Rrs {direction_label(result, k)} (local)", "air/Rrs_local", "1/sr", k)
    for i, depth in enumerate(result.coords["depth"]):
        where = "0-" if depth == 0.0 else f"{depth:g} m"
        row(f"Ed({where})", "Ed", "W/m2", i)
        row(f"Eu({where})", "Eu", "W/m2", i)
        row(f"Eo({where})", "Eo", "W/m2", i)
        row(f"Lu({where}) {how}", "Lu", "W/m2/sr", i)
    # the budget in the order of budget_terms, as a run makes it (a file read back lists its
    # datasets alphabetically): one order for `run` and `show`
    budget = [name for name in result.quantities if name.startswith("budget/")]
    n_layers = sum(name.startswith("budget/absorbed_layer_") for name in budget)
    order = [f"budget/{term}" for _, term, _ in budget_terms(n_layers)] + ["budget/total"]
    for name in order + [name for name in budget if name not in order]:
        row("budget " + name.split("/", 1)[1], name, "1")
    return rows


def estimator_lines(result: Result) -> list[str]:
    """What the nadir and exact-direction columns or rows are: their quantities, and their
    estimators."""
    edges = result.coords.get("theta_edges")
    cap = f"the {edges[-2]:g}-180 deg polar cap's average" if edges is not None \
        and len(edges) > 1 else "the nadir polar cap's average"
    said = []
    if "air/Rrs_nadir" in result:
        if nadir_estimate(result) == "local":
            said.append(f"Rrs nadir: air/Rrs_nadir, {cap}, local (next-event) estimate"
                        + (" (air/Rrs_nadir_crossing: the crossing estimate)"
                           if "air/Rrs_nadir_crossing" in result else "")
                        + (UNBIASED_SPECTRAL_CAP if unbiased_local_nadir(result) else ""))
        else:
            said.append(f"Rrs nadir: air/Rrs_nadir, {cap}, crossing estimate (photons leaving "
                        f"through the cap{local_nadir_hint(result)})")
    ks = local_directions(result)
    if len(ks):
        which = ", ".join(f"Rrs {direction_label(result, k)}" for k in ks)
        said.append(f"{which}: air/Rrs_local in the exact direction{'s' if len(ks) > 1 else ''} "
                    "(theta, phi of travel, deg) of tallies.local_directions_deg, local "
                    "(next-event) estimate: heavy-tailed with forward-peaked phase functions "
                    "(Petzold, Fournier-Forand), far more through a wind-roughened sea, whose "
                    "error bars may understate it many times (compare seeds)")
    return [line for text in said
            for line in textwrap.wrap(text, 100, initial_indent="  ", subsequent_indent="    ")]


# a spectral run's nadir cap without scattering biased toward straight up (the analog walk,
# or upward_fraction: null) is heavy-tailed in the bands where the hero's MIS weights swing
# most: 7-16% low at 600-700 nm with 2-4 x 10^4 photons, z down to -9 (a user's review,
# configs/case1_spectral.yaml, 2026-11-29)
UNBIASED_SPECTRAL_CAP = ("; without upward-biased scattering (estimator.upward_fraction) it is "
                         "heavy-tailed in a spectral run and may read low with error bars that "
                         "do not show it; use upward_fraction auto or 0.1, or many more photons")

# a one-wavelength run's, where auto leaves the bias off unless the depth windows are on
# (scene/weight_window.upward_fraction): its error and time are the few packets' that travel
# near straight up (kernel/upward.py); a user's review (Case-1 Chl 1 at 490 nm, 10^5 photons,
# 2026-11-29) measured Rrs nadir at 9.6% without the bias and 3.6% with 0.1, at 2.2 times the
# photons per second: 17 times the figure of merit (benchmarks/bench.md, clear ocean: 25x)
UNBIASED_CAP = ("; without upward-biased scattering its variance comes from the few packets "
                "travelling near straight up: estimator.upward_fraction: 0.1 (implicit walk) "
                "gives it several to tens of times the figure of merit")


def unbiased_local_nadir(result: Result) -> bool:
    """Rrs nadir is the local estimate, in scattering water, without upward-biased scattering
    (UNBIASED_SPECTRAL_CAP, UNBIASED_CAP); water that does not scatter has no such variance
    (a user's review: the note was printed for configs/snell_window.yaml)."""
    scatters = "b" not in result.iops or bool(np.any(np.asarray(result.iops["b"]) > 0.0))
    return "air/Rrs_nadir" in result and nadir_estimate(result) == "local" and scatters \
        and not result.attrs.get("upward_fraction", 0)


def local_nadir_hint(result: Result) -> str:
    """What the crossing estimate's summary line adds: how to get the cap's local estimate, or
    why the scene cannot have it."""
    from pydantic import TypeAdapter

    from ..config import Bottom, Surface, bottom_has_mirror
    from ..config.surface import MAX_CAP_MSS
    try:
        scene = stored_scene(result.config_yaml)
        surface = Surface(**scene["surface"])
        bottom = TypeAdapter(Bottom).validate_python(scene["bottom"])
    except (KeyError, TypeError, ValueError):
        return ""
    if bottom_has_mirror(bottom):
        return "; a mirror bottom has no density for the local estimate"
    if not surface.cap_lobe_tabulated():
        return ("; the cap's local estimate through waves needs isotropic slopes (no "
                f"wind_direction_deg) of mean square slope <= {MAX_CAP_MSS}")
    return "; tallies.nadir_estimator: local gives the cap's local estimate"


def illumination_lines(result: Result) -> list[str]:
    """Where Ed(0+) came from, for a spectral file: the sun, the spectrum model or table and
    the sky's share of Ed(0+) over the band (none if the file does not say)."""
    light = stored_illumination(result)
    if light is None:
        return []
    model, zenith = light["spectrum_model"], light["sun_zenith_deg"]
    diffuse = np.atleast_1d(result.attrs.get("illumination_diffuse_fraction", []))
    wl = result.coords["wavelength"]
    where = "sun_position" if light.get("sun_position") else "sun_zenith_deg"
    line = f"illumination: sun at {zenith:.2f} deg from the zenith ({where}), spectrum {model}"
    if len(diffuse) == len(wl) and len(wl):
        line += (f"; sky share of Ed(0+) {diffuse[0]:.3f} at {wl[0]:g} nm .. {diffuse[-1]:.3f} "
                 f"at {wl[-1]:g} nm, mean {diffuse.mean():.3f}")
        if model != "flat":
            line += " (per wavelength: `oceanmc show FILE --config`)"
    return textwrap.wrap(line, 100, initial_indent="  ", subsequent_indent="    ")


def sun_position_lines(result: Result) -> list[str]:
    """A one-wavelength file's sun, where the scene gave it by date, time and place
    (sun_position): the zenith angle that came to (a spectral file's illumination line says
    it), else nothing."""
    light = stored_illumination(result)
    if light is None or not light.get("sun_position"):
        return []
    return [f"  sun at {light['sun_zenith_deg']:.2f} deg from the zenith (sun_position)"]


def stored_illumination(result: Result) -> dict | None:
    """The stored scene's illumination mapping, its sun_zenith_deg a float, and its spectrum's
    model as spectrum_model; None where the file does not say (an unreadable or older
    config)."""
    try:
        light = stored_scene(result.config_yaml)["illumination"]
        return dict(light, sun_zenith_deg=float(light["sun_zenith_deg"]),
                    spectrum_model=str(light["spectrum"]["model"]))
    except (KeyError, TypeError, ValueError):
        return None


# the columns of a spectral run's table: (heading, quantity, depth index or None); the exact
# directions of local_directions_deg follow Rrs nadir
SPECTRAL_COLUMNS = (("Ed(0+)", "air/Ed", None), ("Rrs nadir", "air/Rrs_nadir", None),
                    ("Eu(0+)", "air/Eu", None),
                    ("Ed(z1)", "Ed", 0), ("Eu(z1)", "Eu", 0), ("Eo(z1)", "Eo", 0),
                    ("leaving", "budget/water_leaving", None), ("total", "budget/total", None))


# the parts of the light (add_parts) as the summary's headings and the plots' legends name them
PART_LABELS = {"elastic": "elastic", "raman": "Raman",
               "chlorophyll_fluorescence": "fluorescence", "cdom_fluorescence": "CDOM fluor."}


def light_parts(result: Result) -> list[str]:
    """The parts of a run with inelastic light (attribute inelastic_parts: elastic, then each
    process); [] without inelastic light."""
    parts = str(result.attrs.get("inelastic_parts", "")).split()
    return parts if len(parts) > 1 else []


def lowest_requested(wavelengths: np.ndarray, added: np.ndarray) -> float:
    """The lowest wavelength (nm) the scene asked for, of a grid that also holds the wavelengths
    a run added for the excitation of inelastic light."""
    return float(min(w for w in wavelengths if not np.isclose(added, w).any()))


def wavelength_ranges(wavelengths: np.ndarray) -> str:
    """Sorted wavelengths in few words: runs of three or more at one step as '340-390 nm
    (10 nm steps)', the others one by one ('405 nm')."""
    pieces = []
    start = 0
    while start < len(wavelengths):
        end = start + 1   # the run is wavelengths[start:end]
        step = wavelengths[end] - wavelengths[start] if end < len(wavelengths) else 0.0
        while end < len(wavelengths) and np.isclose(wavelengths[end] - wavelengths[end - 1],
                                                    step):
            end += 1
        if end - start >= 3:
            pieces.append(f"{wavelengths[start]:g}-{wavelengths[end - 1]:g} nm ({step:g} nm "
                          "steps)")
        else:   # two at one step: the first alone, the second may begin a run
            end = start + 1
            pieces.append(f"{wavelengths[start]:g} nm")
        start = end
    return ", ".join(pieces)


def process_descriptions(result: Result) -> list[str]:
    """Each inelastic process of a run with its settings, as the stored scene has them (with
    the defaults filled in), so that a comparison (e.g. with HydroLight) can check them; the
    parts' names alone where the stored scene cannot be read."""
    from ..config.inelastic import Inelastic
    try:
        inelastic = Inelastic(**stored_scene(result.config_yaml)["water"]["inelastic"])
    except (KeyError, TypeError, ValueError):
        return [PART_LABELS.get(part, part) for part in light_parts(result)[1:]]
    said = []
    for name, process in inelastic.processes():
        if name == "raman":
            said.append(f"Raman scattering by water (b_R {process.b488_per_m:g} 1/m at 488 nm, "
                        f"as (488/l)^{process.exponent:g}; phase function 1 + "
                        f"{process.phase_beta:g} cos^2)")
        elif name == "chlorophyll_fluorescence":
            low, high = process.excitation_range_nm
            said.append(f"chlorophyll fluorescence (quantum yield {process.quantum_yield:g}, "
                        f"{process.peak_nm:g} nm, sigma {process.sigma_nm:g} nm, excited "
                        f"{low:g}-{high:g} nm)")
        elif name == "cdom_fluorescence":
            low, high = process.excitation_range_nm
            said.append(f"CDOM fluorescence (Hawes 1992, quantum efficiency x "
                        f"{process.a0_scale:g}, excited {low:g}-{high:g} nm)")
        else:
            said.append(PART_LABELS.get(name, name))
    return said


def inelastic_lines(result: Result) -> list[str]:
    """For a run with inelastic light: the processes that were on, the parts every quantity is
    split into, and the wavelengths traced beyond those asked for (attribute
    wavelengths_added_nm), whose own inelastic light lacks what would be excited below the
    traced grid (Raman light at 370 nm comes from 323-335 nm). [] without inelastic light."""
    parts = light_parts(result)
    if not parts:
        return []
    said = [f"inelastic light: {', '.join(process_descriptions(result))}; every quantity but "
            "the ratios is also split into parts that add up to it: "
            f"{', '.join(p + '/' for p in parts)} (e.g. {parts[1]}/air/Rrs_nadir); elastic/ "
            "is the light no process shifted, after their losses (not a run without them)"]
    if "wavelengths_added_nm" in result.attrs:
        added = np.atleast_1d(np.asarray(result.attrs["wavelengths_added_nm"], dtype=float))
        wavelengths = result.coords["wavelength"]
        if len(added) == 0:
            said.append("traced no wavelength beyond those asked for: they hold the excitation "
                        "of the inelastic light")
        else:
            first = lowest_requested(wavelengths, added)
            below = f", though those below {first:g} nm lack the inelastic light excited " \
                f"below {wavelengths[0]:g} nm" if (added < first).any() else ""
            said.append(f"traced also {wavelength_ranges(np.sort(added))} for the excitation "
                        f"of inelastic light; reported with the rest{below}")
    return [line for text in said
            for line in textwrap.wrap(text, SUMMARY_WIDTH, initial_indent="  ",
                                      subsequent_indent="    ")]


def rrs_parts_table(result: Result) -> list[str]:
    """For a run with inelastic light: Rrs nadir of each part of the light per wavelength, its
    relative standard error and its share of the whole Rrs nadir; [] without inelastic light or
    without Rrs nadir. The elastic part and all three processes fit SUMMARY_WIDTH (96
    characters)."""
    parts = [part for part in light_parts(result) if f"{part}/air/Rrs_nadir" in result]
    if not parts or "air/Rrs_nadir" not in result:
        return []
    whole = result["air/Rrs_nadir"]
    head = ("Rrs nadir by part of the light: value, relative standard error and share of the "
            f"whole ({', '.join(f'{p}/air/Rrs_nadir' for p in parts)})")
    lines = [""] + textwrap.wrap(head, SUMMARY_WIDTH, initial_indent="  ",
                                 subsequent_indent="  ")
    lines.append(f"  {'nm':>6}" + "".join(f" {PART_LABELS.get(p, p):>15} {'share':>6}"
                                          for p in parts))
    for k, wavelength in enumerate(result.coords["wavelength"]):
        row = f"  {wavelength:>6g}"
        for part in parts:
            value = result[f"{part}/air/Rrs_nadir"][k]
            share = value / whole[k] if whole[k] != 0.0 else 0.0
            row += f" {value_cell(value, result.stderr(f'{part}/air/Rrs_nadir')[k]):>15}" \
                f" {share:>6.1%}"
        lines.append(row)
    return lines


def format_spectrum(result: Result) -> list[str]:
    """A spectral run as a table: one row per wavelength, the headline quantities in columns
    (z1: the first tally depth), each value with its relative standard error in %, in blocks of
    columns no wider than SUMMARY_WIDTH, and with inelastic light Rrs nadir by part of the light;
    then what the Rrs columns are (their estimators), the inelastic processes and the wavelengths
    added for them, and where the light came from."""
    depths = result.coords["depth"]
    first = "0-" if depths[0] == 0.0 else f"{depths[0]:g} m"
    columns = []
    for head, name, index in SPECTRAL_COLUMNS:
        if name in result:
            columns.append((head.replace("z1", first), name, (slice(None), index)))
        if name == "air/Rrs_nadir":
            columns += [(f"Rrs {direction_label(result, k)}", "air/Rrs_local", (slice(None), k))
                        for k in local_directions(result)]
    cells = []   # per column: its cell per wavelength
    for _, name, (_, index) in columns:
        column = []
        for k in range(len(result.coords["wavelength"])):
            value, err = result[name][k], result.stderr(name)[k]
            if index is not None:
                value, err = value[index], err[index]
            column.append(value_cell(value, err))
        cells.append(column)
    # the quantities at the surface (Ed(0+), the Rrs columns, Eu(0+)) first, then those in the
    # water and the budget
    surface = next(i for i, (_, name, _) in enumerate(columns + [("", "Ed", 0)])
                   if name in ("Ed", "Eu", "Eo") or name.startswith("budget/"))
    lines = spectral_blocks(result.coords["wavelength"], [head for head, _, _ in columns], cells,
                            (range(0, surface), range(surface, len(columns))))
    lines += rrs_parts_table(result)
    lines += estimator_lines(result)
    lines += inelastic_lines(result)
    lines += illumination_lines(result)
    lines.append("  (value and relative standard error; irradiances in the units of Ed(0+), "
                 "Rrs in 1/sr,")
    lines.append("  budget fractions of Ed(0+); every quantity per wavelength in the file)")
    return lines


# standard errors from fewer batches than this are themselves too uncertain to trust: from n
# batches the standard error's own relative error is about 1 / sqrt(2 (n - 1)), 38% at 4
RELIABLE_BATCHES = 8


def stored_scene(config_yaml: str) -> dict:
    """The stored scene (attribute config_yaml) as a mapping, {} where the text is not a YAML
    mapping (an unreadable or foreign file): what the summary's lines read it for is then
    missing, as a key is."""
    import yaml
    try:
        scene = yaml.safe_load(config_yaml)
    except yaml.YAMLError:
        return {}
    return scene if isinstance(scene, dict) else {}


def planned_batches(config_yaml: str) -> int | None:
    """The batches the stored scene asked for (a partial file holds fewer whole ones); None
    where the stored text does not say."""
    try:
        return int(stored_scene(config_yaml)["batches"])
    except (KeyError, TypeError, ValueError):
        return None


def completeness_line(result: Result) -> str | None:
    """One line on a partial file (N of M batches whole) and on standard errors from fewer than
    RELIABLE_BATCHES batches; None for a complete file of enough batches."""
    a = result.attrs
    done = int(a["batches"])
    if not a.get("partial", False) and done >= RELIABLE_BATCHES:
        return None
    total = planned_batches(result.config_yaml)
    of = f" of {total}" if total is not None else ""
    head = f"  PARTIAL: {done}{of} batches whole (a stopped run; the estimates use them only)" \
        if a.get("partial", False) else f"  note: {done} batches"
    if done == 0:
        return head + "; no batch is whole yet: the file holds no estimate, only the state to " \
            "resume from"
    if done < RELIABLE_BATCHES:
        return head + f"; standard errors from fewer than {RELIABLE_BATCHES} batches are " \
            "unreliable"
    return head


def single_wavelength(result: Result) -> float | None:
    """The wavelength (nm) of a run that traced one, which its file holds no wavelength
    coordinate for; None for a monochromatic scene (no wavelength) or several."""
    from pydantic import TypeAdapter

    from ..config.wavelengths import Wavelengths, grid
    try:
        value = stored_scene(result.config_yaml).get("wavelengths_nm")
        wavelengths = grid(None if value is None
                           else TypeAdapter(Wavelengths).validate_python(value))
    except (KeyError, TypeError, ValueError):
        return None
    return float(wavelengths[0]) if len(wavelengths) == 1 and np.isfinite(wavelengths[0]) \
        else None


def data_file_lines(result: Result) -> list[str]:
    """The data files the scene read (tables of IOPs, water absorption, phase functions,
    spectra, BRDFs, sky maps), as the config names them, each with the start of the sha256 of
    its content when the run read it (attribute data_files_sha256), so that a result says what
    it was made from after the file has moved or changed."""
    try:
        hashes = json.loads(str(result.attrs.get("data_files_sha256", "{}")))
    except json.JSONDecodeError:
        return []
    if not hashes:
        return []
    keys = {}
    try:   # (the keys that name them: a stored config loads without its files)
        from ..config import ConfigError, load_config
        from ..config.loading import data_file_fields
        config = load_config(stored_scene(result.config_yaml))
        keys = {getattr(model, attribute): key
                for model, attribute, key in data_file_fields(config)}
    except (ConfigError, TypeError, ValueError):
        pass
    text = "data files (sha256 when run): " + "; ".join(
        (f"{keys[path]} = " if path in keys else "") + f"{path} ({digest[:12]})"
        for path, digest in hashes.items())
    return textwrap.wrap(text, SUMMARY_WIDTH, initial_indent="  ", subsequent_indent="    ",
                         break_on_hyphens=False, break_long_words=False)


def format_iops(result: Result) -> str:
    """The IOPs the run used (the file's group iops) as text for `oceanmc show --iops`: per
    layer, a table by wavelength of a, b, bb, c (1/m), bb/b and the single-scattering albedo
    w0 = b/c, and the bottom's reflectance where it has one; a layer of a depth profile is one
    of the homogeneous sublayers the run traced."""
    iops = result.iops
    if not iops:
        return "  IOPs: this file holds none (it was written before oceanmc stored them)"
    wavelengths = np.atleast_1d(iops["wavelength"])
    tops, thicknesses = iops["layer_top"], iops["layer_thickness"]
    lines = [f"  IOPs the run used ({len(tops)} layer{'s' if len(tops) > 1 else ''}; the "
             "file's group iops), 1/m:"]

    def table(headings: list[str], columns: list[np.ndarray]) -> list[str]:
        rows = [f"  {'nm':>6}" + "".join(f"{h:>{IOP_CELL}}" for h in headings)]
        for k, wavelength in enumerate(wavelengths):
            nm = f"{wavelength:>6g}" if np.isfinite(wavelength) else f"{'-':>6}"
            rows.append(f"  {nm}" + "".join(f"{column[k]:>{IOP_CELL}.5g}" for column in columns))
        return rows
    with np.errstate(divide="ignore", invalid="ignore"):
        for i, (top, thickness) in enumerate(zip(tops, thicknesses)):
            a, b, bb, c = (np.atleast_1d(iops[name][i]) for name in ("a", "b", "bb", "c"))
            bottom = f"{top + thickness:g} m" if np.isfinite(thickness) else "infinite depth"
            lines.append(f"  layer {i + 1}: {top:g} m to {bottom}")
            lines += table(["a", "b", "bb", "c", "bb/b", "w0 = b/c"],
                           [a, b, bb, c, np.where(b > 0.0, bb / b, np.nan),
                            np.where(c > 0.0, b / c, np.nan)])
    if "bottom_reflectance" in iops:
        lines += ["  bottom: its model's reflectance rho (a lambertian bottom's Eu/Ed; a minnaert",
                  "  bottom reflects 2 rho cos^k t_i / (k + 2))"]
        lines += table(["reflectance"], [np.atleast_1d(iops["bottom_reflectance"])])
    return "\n".join(lines)


# a column of `oceanmc show --iops`: a value to 5 significant digits (1.2345e-05) and its gap
IOP_CELL = 13


def format_summary(result: Result) -> str:
    a = result.attrs
    lines = [
        f"{a.get('name', '')}",
        f"  {a['photons']:,} photons in {a['batches']} batches on {a['threads']} thread(s): "
        f"{a['wall_time_s']:.2f} s, {a['photons_per_s']:,.0f} photons/s "
        f"(start-up {a['startup_time_s']:.2f} s)",
    ]
    if "merged_from" in a:   # (oceanmc merge: the times above are the runs' sums)
        lines.append(f"  merged from {a['merged_from']} runs (seeds {a.get('seeds')}); the "
                     "times are their sums")
    at = single_wavelength(result)
    if at is not None and "wavelength" in result.coords:   # (and those its excitation needs)
        lines.append(f"  asked for {at:g} nm alone; the table holds the wavelengths traced for "
                     "its excitation as well")
    elif at is not None:
        lines.append(f"  at {at:g} nm (the scene's one wavelength)")
    said = completeness_line(result)
    if said is not None:
        lines.append(said)
    lines += data_file_lines(result)
    if "wavelength" in result.coords:
        return "\n".join(lines + format_spectrum(result))
    lines += sun_position_lines(result)
    lines.append(f"  {'quantity':<28}{'units':<9}{'value':>13}{'std err':>12}{'rel err':>10}")
    for label, units, value, err in summary_rows(result):
        rel = abs(err / value) if value != 0.0 else 0.0
        lines.append(f"  {label:<28}{units:<9}{value:>13.6g}{err:>12.3g}{rel:>10.2%}")
    if unbiased_local_nadir(result):
        lines += textwrap.wrap("note: Rrs nadir (local)" + UNBIASED_CAP, 100,
                               initial_indent="  ", subsequent_indent="    ")
    return "\n".join(lines)
