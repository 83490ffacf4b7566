"""oceanmc: Monte Carlo radiative transfer for natural waters.

    import oceanmc
    config = oceanmc.load_config("configs/default.yaml")
    result = oceanmc.simulate(config)
    result["Ed"], result.stderr("Ed")
    result.save("out.h5"); oceanmc.load_result("out.h5")
"""
__version__ = "0.1.0"

from .config import ConfigError, SceneConfig, load_config  # noqa: E402
from .results import Result, load_result  # noqa: E402
from .simulation import simulate  # noqa: E402

__all__ = ["ConfigError", "SceneConfig", "Result", "load_config", "load_result", "simulate",
           "__version__"]
