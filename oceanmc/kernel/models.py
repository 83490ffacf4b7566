"""Integer model ids shared by the packers (oceanmc/scene/, which pack them) and the kernel (which
dispatches on them); their names are in kernel/registry.py. Module-level ints are compile-time
constants for Numba."""

# Phase function components (a layer's phase function is a weighted sum of components).
PHASE_ISOTROPIC = 0
PHASE_QUADRATIC = 1      # (1 + beta cos^2): Rayleigh-like (beta = 1), pure sea water (0.835)
PHASE_HG = 2             # Henyey-Greenstein (g)
PHASE_TABULATED = 3      # piecewise-linear 2 pi p sin(psi) on nodes: Petzold, FF, user tables

# Air-water surfaces.
SURFACE_NONE = 0         # no interface (index-matched)
SURFACE_FLAT = 1         # flat: Fresnel + Snell
SURFACE_COX_MUNK = 2     # wind-roughened: Gaussian facet slopes (Cox & Munk 1954)

# Bottoms.
BOTTOM_NONE = 0          # infinitely deep water: no bottom plane is ever reached
BOTTOM_BLACK = 1
BOTTOM_LAMBERTIAN = 2
BOTTOM_MINNAERT = 3
BOTTOM_SPECULAR = 4
BOTTOM_LAMBERTIAN_SPECULAR = 5   # rho_d/pi + rho_s mirror (a delta component)
BOTTOM_GGX = 6           # GGX / Trowbridge-Reitz microfacets, Smith shadowing, Fresnel (+ rho_d/pi)
BOTTOM_HAPKE = 7         # Hapke (1981/1993) with the shadow-hiding opposition (hot-spot) term
BOTTOM_TABLE = 8         # measured BRDF on an angular grid (isotropic or anisotropic), from a file

# The bottom parameter array (the bottom pool, float64): the model's scalar parameters in slots
# 0 .. BRDF_NSCALARS - 1, then a header, then any tables (scene/brdf_tables.py packs it).
# Offsets are stored as floats (exact below 2^53) and read with int().
BRDF_NSCALARS = 8
BRDF_SAMPLER = 8         # 0: the model's own sampler; 1: the general tabulated sampler
BRDF_SAMPLER_AT = 9      # offset of the general sampler's tables (brdf/general.py)
BRDF_TABLE_AT = 10       # offset of a measured BRDF table (brdf/table.py)
BRDF_HEADER = 16         # length of the fixed part

# Sky radiance shapes.
SKY_UNIFORM = 0
SKY_CARDIOIDAL = 1       # L ~ 1 + 2 cos(zenith angle): the CIE standard overcast sky
SKY_MAP = 2              # a tabulated radiance map, piecewise constant on its cells (sky_maps.py)
SKY_HARRISON_COOMBES = 3  # Harrison & Coombes (1988) clear sky; a fine map as the proposal
SKY_MAP_COSINE = 4       # a map sampled cosine-weighted, each photon weighted by its cell's L

# Collision channels (kernel/channels/).
CHANNEL_ELASTIC = 0
CHANNEL_RAMAN = 1                     # Raman scattering by water (channels/inelastic.py)
CHANNEL_CHLOROPHYLL_FLUORESCENCE = 2  # fluorescence of phytoplankton (channels/inelastic.py)

# Budget terms (columns of the budget tally); absorbed-per-layer columns follow BUDGET_LAYERS.
BUDGET_SURFACE_REFLECTION = 0
BUDGET_WATER_LEAVING = 1
BUDGET_BOTTOM = 2
BUDGET_LOST_BELOW = 3
BUDGET_TRUNCATED = 4     # weight still alive when a photon hit the max_events safety limit
BUDGET_SHIFTED_OUT = 5   # weight an inelastic process took from this wavelength
BUDGET_SHIFTED_IN = 6    # weight an inelastic process gave to this wavelength
BUDGET_LAYERS = 7

# Water flux tally columns.
FLUX_ED = 0
FLUX_EU = 1
FLUX_EOD = 2
FLUX_EOU = 3
