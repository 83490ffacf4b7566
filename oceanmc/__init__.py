"""oceanmc: Monte Carlo radiative transfer for natural waters.

    import oceanmc
    config = oceanmc.load_config("configs/default.yaml")
    result = oceanmc.simulate(config)
    result["Ed"], result.stderr("Ed")
    result.save("out.h5"); oceanmc.load_result("out.h5")
    oceanmc.derive(result)["Kd"].value                          # Kd, R, Q, t_up, ...
    oceanmc.merge_results([result, other])                     # runs of one scene, other seeds
    lut = oceanmc.sweep("lut.yaml", "lut.nc", workers=2)      # an xarray.Dataset

The names below are imported on first use (PEP 562), so that `import oceanmc` and commands that
need little (`oceanmc --help`) do not pay for numba, h5py and pydantic.
"""
from typing import TYPE_CHECKING

__version__ = "0.1.0"

# public name -> the submodule that defines it
_LAZY = {
    "ConfigError": "config",
    "SceneConfig": "config",
    "load_config": "config",
    "Result": "run.result",
    "load_result": "run.hdf5",
    "simulate": "run.simulation",
    "derive": "run.derived",
    "merge_results": "run.merge",
    "sweep": "sweeps",
}
# the subpackages, as attributes (the data flow: config -> scene -> kernel -> run -> sweeps)
_SUBMODULES = frozenset({"config", "registry", "scene", "kernel", "run", "sweeps"})

__all__ = ["ConfigError", "SceneConfig", "Result", "load_config", "load_result", "simulate",
           "derive", "merge_results", "sweep", "__version__"]

if TYPE_CHECKING:
    from .config import ConfigError, SceneConfig, load_config
    from .run.derived import derive
    from .run.hdf5 import load_result
    from .run.merge import merge_results
    from .run.result import Result
    from .run.simulation import simulate
    from .sweeps import sweep


def __getattr__(name: str):
    from importlib import import_module

    if name in _LAZY:
        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | _SUBMODULES)
