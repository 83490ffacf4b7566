"""One entry point for the phase function of a layer: pick a component by its scattering weight,
then sample or evaluate it by model id (ids and names: kernel/registry.py). A layer's components
are comp_start .. comp_start + comp_count - 1 in the medium's pools (kernel/records.py)."""
import math

import numpy as np

from ..compile import hot, kernel, setup
from ..models import PHASE_HG, PHASE_QUADRATIC, PHASE_TABULATED
from . import henyey_greenstein, isotropic, quadratic, tabulated


@kernel
def component_params(medium, floats, k):
    """Component k's two parameters as a tuple of floats."""
    at = medium.comp_params + 2 * k
    return (floats[at], floats[at + 1])


@kernel
def table_at(medium, ints, k):
    """(psi, q, cdf offsets, node count) of component k's table in the float pool (tables on
    the same angle grid share its psi offset)."""
    start = ints[medium.comp_tab_start + k]
    return (medium.tab_psi + ints[medium.comp_psi_start + k], medium.tab_q + start,
            medium.tab_cdf + start, ints[medium.comp_tab_len + k])


@kernel
def guide_at(medium, ints, k):
    """The int pool offset of component k's guide table (tabulated.sample_angle)."""
    return medium.tab_guide + ints[medium.comp_tab_start + k]


@hot
def sample_component(medium, floats, ints, k, u):
    model = ints[medium.comp_model + k]
    if model == PHASE_HG:
        return henyey_greenstein.sample(component_params(medium, floats, k), u)
    if model == PHASE_TABULATED:
        psi_at, q_at, cdf_at, length = table_at(medium, ints, k)
        return tabulated.sample(floats, ints, psi_at, q_at, cdf_at, guide_at(medium, ints, k),
                                length, u)
    if model == PHASE_QUADRATIC:
        return quadratic.sample(component_params(medium, floats, k), u)
    return isotropic.sample(component_params(medium, floats, k), u)


@hot
def evaluate_component(medium, floats, ints, k, cos_psi):
    model = ints[medium.comp_model + k]
    if model == PHASE_HG:
        return henyey_greenstein.evaluate(component_params(medium, floats, k), cos_psi)
    if model == PHASE_TABULATED:
        psi_at, q_at, _, length = table_at(medium, ints, k)
        return tabulated.evaluate(floats, psi_at, q_at, length, cos_psi)
    if model == PHASE_QUADRATIC:
        return quadratic.evaluate(component_params(medium, floats, k), cos_psi)
    return isotropic.evaluate(component_params(medium, floats, k), cos_psi)


@hot
def pick(medium, floats, ints, layer, wavelength, u_pick):
    """The component of the layer's mixture at wavelength index `wavelength` that u_pick
    chooses, with probability b_k / b."""
    k = ints[medium.comp_start + layer]
    last = k + ints[medium.comp_count + layer] - 1
    cumweight = medium.comp_cumweight + wavelength * medium.n_comps
    while k < last and u_pick >= floats[cumweight + k]:
        k += 1
    return k


@hot
def sample_cos(medium, floats, ints, layer, wavelength, u_pick, u):
    """cos(psi) from the layer's phase function at wavelength index `wavelength`; u_pick chooses
    the component of a mixture (it is ignored for a single component, so the caller need not
    draw it), u the angle."""
    return sample_component(medium, floats, ints,
                            pick(medium, floats, ints, layer, wavelength, u_pick), u)


@hot
def sample_angle(medium, floats, ints, k, u):
    """(cos psi, psi, psi grid offset, node) sampled from component k; for a tabulated one the
    node i of its angle grid with psi[i] <= psi <= psi[i + 1], which spares a caller that
    evaluates tables on the same grid their search; otherwise grid offset and node are -1."""
    if ints[medium.comp_model + k] == PHASE_TABULATED:
        psi_at, q_at, cdf_at, length = table_at(medium, ints, k)
        node, angle = tabulated.sample_angle(floats, ints, psi_at, q_at, cdf_at,
                                             guide_at(medium, ints, k), length, u)
        return math.cos(angle), angle, psi_at, node
    cos_psi = sample_component(medium, floats, ints, k, u)
    return cos_psi, math.acos(min(1.0, max(-1.0, cos_psi))), -1, -1


@hot
def evaluate(medium, floats, ints, layer, cos_psi):
    """The layer's phase function p(cos_psi) in 1/sr: the b-weighted sum of its components (at
    the first wavelength: local estimates and the upward bias are monochromatic)."""
    first = ints[medium.comp_start + layer]
    total = 0.0
    previous = 0.0
    for k in range(first, first + ints[medium.comp_count + layer]):
        weight = floats[medium.comp_cumweight + k] - previous
        previous = floats[medium.comp_cumweight + k]
        total += weight * evaluate_component(medium, floats, ints, k, cos_psi)
    return total


@setup
def component_density(medium, floats, ints, component, angles):
    """q(psi) = 2 pi p(psi) sin(psi) of one phase function component at each angle (rad), for
    tables built once per scene (a layer's is the mixture of its components' with the shares of
    each wavelength, comp_cumweight); tabulated components are read exactly, without the loss
    of precision of cos(psi) near 0."""
    out = np.empty(angles.shape[0])
    tabulated_model = ints[medium.comp_model + component] == PHASE_TABULATED
    for i in range(angles.shape[0]):
        angle = angles[i]
        if tabulated_model:
            psi_at, q_at, _, length = table_at(medium, ints, component)
            out[i] = tabulated.density(floats, psi_at, q_at, length, angle)
        else:
            out[i] = 2.0 * math.pi * math.sin(angle) * evaluate_component(
                medium, floats, ints, component, math.cos(angle))
    return out
