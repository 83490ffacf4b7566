"""One registry per component kind: each model name the schema (oceanmc/config) accepts, and what
the kernel runs for it, its model id (kernel/models.py) and the module that implements it. The
packers (oceanmc/scene/) look models up here, and tests/test_registry.py fails if a model is in
the schema but not here, here but not in the schema, or here but not reached by the kernel's
dispatch (kernel/*/dispatch.py).

Adding a model: one kernel module, one schema class, one line here, one branch in the kind's
dispatch function."""
from __future__ import annotations

from .kernel import models

# Phase functions: a schema model becomes one or more kernel components (weight, kernel model
# id, parameters, table); scene/medium.py builds them. Kernel phase models and their modules:
PHASE_KERNEL = {
    models.PHASE_ISOTROPIC: "isotropic",
    models.PHASE_QUADRATIC: "quadratic",
    models.PHASE_HG: "henyey_greenstein",
    models.PHASE_TABULATED: "tabulated",
}
# schema phase models -> kernel phase models they are made of
PHASE = {
    "isotropic": (models.PHASE_ISOTROPIC,),
    "rayleigh": (models.PHASE_QUADRATIC,),
    "pure_water": (models.PHASE_QUADRATIC,),
    "henyey_greenstein": (models.PHASE_HG,),
    "two_term_hg": (models.PHASE_HG,),
    "fournier_forand": (models.PHASE_TABULATED,),
    "petzold": (models.PHASE_TABULATED,),
    "table": (models.PHASE_TABULATED,),
    "mixture": (),   # a weighted sum of the others
}

# Water constituents (config/components.py): schema model -> module in optics/components/
CONSTITUENT = {
    "pure_water": "pure_water",
    "chlorophyll": "chlorophyll",
    "case1": "case1",
    "cdom": "cdom",
    "particles": "particles",
    "table": "table",
    "constant": "constant",
}

# Bottom BRDFs: schema model -> (kernel model id, module in kernel/brdf/ or None)
BOTTOM = {
    "none": (models.BOTTOM_NONE, None),
    "black": (models.BOTTOM_BLACK, None),
    "lambertian": (models.BOTTOM_LAMBERTIAN, "lambertian"),
    "minnaert": (models.BOTTOM_MINNAERT, "minnaert"),
    "specular": (models.BOTTOM_SPECULAR, "specular"),
    "lambertian_specular": (models.BOTTOM_LAMBERTIAN_SPECULAR, "lambertian_specular"),
    "ggx": (models.BOTTOM_GGX, "ggx"),
    "hapke": (models.BOTTOM_HAPKE, "hapke"),
    "table": (models.BOTTOM_TABLE, "table"),
    # an areal mixture of one shape: packed as the lambertian or minnaert bottom of the
    # fraction-weighted reflectance (optics/bottom.py), no kernel model of its own
    "mixture": (None, None),
}

# Air-water surfaces: schema model -> (kernel model id, module in kernel/surface/)
SURFACE = {
    "none": (models.SURFACE_NONE, "index_matched"),
    "flat": (models.SURFACE_FLAT, "flat"),
    "cox_munk": (models.SURFACE_COX_MUNK, "cox_munk"),
}

# Collision channels: name -> (kernel model id, module in kernel/channels/). Elastic scattering
# is every scene's; inelastic processes (water.inelastic, each a module in optics/inelastic/ of
# the same name) add theirs, all run by channels/inelastic.py from their packed transfer.
# The kernel reads no inelastic channel's id (MEDIUM channel_model only records which process
# a channel is), so CDOM fluorescence's is kept here rather than in kernel/models.py, whose
# every edit starts a fresh compile cache (kernel/compile.py) and a new kernel commit for the
# benchmark and validation reports; it moves there with the next kernel change.
CHANNEL_CDOM_FLUORESCENCE = 3
CHANNEL = {
    "elastic": (models.CHANNEL_ELASTIC, "elastic"),
    "raman": (models.CHANNEL_RAMAN, "inelastic"),
    "chlorophyll_fluorescence": (models.CHANNEL_CHLOROPHYLL_FLUORESCENCE, "inelastic"),
    "cdom_fluorescence": (CHANNEL_CDOM_FLUORESCENCE, "inelastic"),
}

# Sky radiance shapes: schema name -> kernel model id; a map ({map: FILE}) is SKY_MAP or, with
# sampling: cosine, SKY_MAP_COSINE. All are sampled by kernel/sources.py.
SKY = {
    "uniform": models.SKY_UNIFORM,
    "cardioidal": models.SKY_CARDIOIDAL,
    "overcast": models.SKY_CARDIOIDAL,
    "harrison_coombes": models.SKY_HARRISON_COOMBES,
}
SKY_MAP = {"importance": models.SKY_MAP, "cosine": models.SKY_MAP_COSINE}


def bottom_id(name: str) -> int:
    return BOTTOM[name][0]


def surface_id(name: str) -> int:
    return SURFACE[name][0]
