"""Integer model ids shared by scene.py (which packs them) and the kernel (which dispatches on
them). Module-level ints are compile-time constants for Numba."""

# Phase function components (a layer's phase function is a weighted sum of components).
PHASE_ISOTROPIC = 0
PHASE_QUADRATIC = 1      # (1 + beta cos^2): Rayleigh-like (beta = 1), pure sea water (0.835)
PHASE_HG = 2             # Henyey-Greenstein (g)
PHASE_TABULATED = 3      # piecewise-linear 2 pi p sin(psi) on nodes: Petzold, FF, user tables

# Bottoms.
BOTTOM_NONE = 0          # infinitely deep water: no bottom plane is ever reached
BOTTOM_BLACK = 1
BOTTOM_LAMBERTIAN = 2
BOTTOM_MINNAERT = 3
BOTTOM_SPECULAR = 4

# Sky radiance shapes.
SKY_UNIFORM = 0
SKY_CARDIOIDAL = 1       # L ~ 1 + 2 cos(zenith angle)

# Budget terms (columns of the budget tally); absorbed-per-layer columns follow BUDGET_LAYERS.
BUDGET_SURFACE_REFLECTION = 0
BUDGET_WATER_LEAVING = 1
BUDGET_BOTTOM = 2
BUDGET_LOST_BELOW = 3
BUDGET_TRUNCATED = 4     # weight still alive when a photon hit the max_events safety limit
BUDGET_LAYERS = 5

# Water flux tally columns.
FLUX_ED = 0
FLUX_EU = 1
FLUX_EOD = 2
FLUX_EOU = 3
