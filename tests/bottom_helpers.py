"""What the tests of bottoms that vary with wavelength share: a 2 m water layer over the bottom
under test, three wavelengths, a scene dict built from them."""
import copy

WAVELENGTHS = [440.0, 550.0, 670.0]
WATER = {"layers": [{"thickness_m": 2.0, "a": 0.05, "b": 0.1}]}


def scene_dict(bottom, wavelengths=WAVELENGTHS, **changes):
    """A small spectral scene over `bottom` (wavelengths None: monochromatic); `changes`
    replace top-level keys."""
    out = {"photons": 400, "batches": 2, "seed": 5, "water": copy.deepcopy(WATER),
           "bottom": bottom, "tallies": {"depths_m": [0, 2]}}
    if wavelengths is not None:
        out["wavelengths_nm"] = wavelengths
    out.update(changes)
    return out
