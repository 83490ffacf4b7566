"""One entry point for the phase function of a layer: pick a component by its scattering weight,
then sample or evaluate it by model id (ids and names: kernel/registry.py). A layer's components
are comp_start .. comp_start + comp_count - 1 in the medium's pools (kernel/records.py)."""
import math

import numpy as np

from ..compile import hot, kernel, setup
from ..models import PHASE_HG, PHASE_QUADRATIC, PHASE_TABULATED
from . import henyey_greenstein, isotropic, quadratic, tabulated


@kernel
def component_params(medium, mf, k):
    """Component k's two parameters as a tuple of floats."""
    at = medium.comp_params + 2 * k
    return (mf[at], mf[at + 1])


@kernel
def table_at(medium, mi, k):
    """(psi, q, cdf offsets, node count) of component k's table in the float pool (tables on
    the same angle grid share its psi offset)."""
    start = mi[medium.comp_tab_start + k]
    return (medium.tab_psi + mi[medium.comp_psi_start + k], medium.tab_q + start,
            medium.tab_cdf + start, mi[medium.comp_tab_len + k])


@kernel
def guide_at(medium, mi, k):
    """The int pool offset of component k's guide table (tabulated.sample_angle)."""
    return medium.tab_guide + mi[medium.comp_tab_start + k]


@hot
def sample_component(medium, mf, mi, k, u):
    model = mi[medium.comp_model + k]
    if model == PHASE_HG:
        return henyey_greenstein.sample(component_params(medium, mf, k), u)
    if model == PHASE_TABULATED:
        psi_at, q_at, cdf_at, length = table_at(medium, mi, k)
        return tabulated.sample(mf, mi, psi_at, q_at, cdf_at, guide_at(medium, mi, k), length,
                                u)
    if model == PHASE_QUADRATIC:
        return quadratic.sample(component_params(medium, mf, k), u)
    return isotropic.sample(component_params(medium, mf, k), u)


@hot
def evaluate_component(medium, mf, mi, k, cos_psi):
    model = mi[medium.comp_model + k]
    if model == PHASE_HG:
        return henyey_greenstein.evaluate(component_params(medium, mf, k), cos_psi)
    if model == PHASE_TABULATED:
        psi_at, q_at, _, length = table_at(medium, mi, k)
        return tabulated.evaluate(mf, psi_at, q_at, length, cos_psi)
    if model == PHASE_QUADRATIC:
        return quadratic.evaluate(component_params(medium, mf, k), cos_psi)
    return isotropic.evaluate(component_params(medium, mf, k), cos_psi)


@hot
def pick(medium, mf, mi, layer, wavelength, u_pick):
    """The component of the layer's mixture at wavelength index `wavelength` that u_pick
    chooses, with probability b_k / b."""
    k = mi[medium.comp_start + layer]
    last = k + mi[medium.comp_count + layer] - 1
    cumweight = medium.comp_cumweight + wavelength * medium.n_comps
    while k < last and u_pick >= mf[cumweight + k]:
        k += 1
    return k


@hot
def sample_cos(medium, mf, mi, layer, wavelength, u_pick, u):
    """cos(psi) from the layer's phase function at wavelength index `wavelength`; u_pick chooses
    the component of a mixture (it is ignored for a single component, so the caller need not
    draw it), u the angle."""
    return sample_component(medium, mf, mi, pick(medium, mf, mi, layer, wavelength, u_pick), u)


@hot
def sample_angle(medium, mf, mi, k, u):
    """(cos psi, psi, psi grid offset, node) sampled from component k; for a tabulated one the
    node i of its angle grid with psi[i] <= psi <= psi[i + 1], which spares a caller that
    evaluates tables on the same grid their search; otherwise grid offset and node are -1."""
    if mi[medium.comp_model + k] == PHASE_TABULATED:
        psi_at, q_at, cdf_at, length = table_at(medium, mi, k)
        node, angle = tabulated.sample_angle(mf, mi, psi_at, q_at, cdf_at,
                                             guide_at(medium, mi, k), length, u)
        return math.cos(angle), angle, psi_at, node
    cos_psi = sample_component(medium, mf, mi, k, u)
    return cos_psi, math.acos(min(1.0, max(-1.0, cos_psi))), -1, -1


@hot
def evaluate(medium, mf, mi, layer, cos_psi):
    """The layer's phase function p(cos_psi) in 1/sr: the b-weighted sum of its components (at
    the first wavelength: local estimates and the upward bias are monochromatic)."""
    first = mi[medium.comp_start + layer]
    total = 0.0
    previous = 0.0
    for k in range(first, first + mi[medium.comp_count + layer]):
        weight = mf[medium.comp_cumweight + k] - previous
        previous = mf[medium.comp_cumweight + k]
        total += weight * evaluate_component(medium, mf, mi, k, cos_psi)
    return total


@setup
def layer_density(medium, mf, mi, layer, wavelength, angles):
    """q(psi) = 2 pi p(psi) sin(psi) of the layer's phase function at wavelength index
    `wavelength`, at each angle (rad), for tables built once per scene; tabulated components
    are read exactly, without the loss of precision of cos(psi) near 0."""
    out = np.empty(angles.shape[0])
    first = mi[medium.comp_start + layer]
    cumweight = medium.comp_cumweight + wavelength * medium.n_comps
    for i in range(angles.shape[0]):
        angle = angles[i]
        total = 0.0
        previous = 0.0
        for k in range(first, first + mi[medium.comp_count + layer]):
            weight = mf[cumweight + k] - previous
            previous = mf[cumweight + k]
            if weight == 0.0:
                continue
            if mi[medium.comp_model + k] == PHASE_TABULATED:
                psi_at, q_at, _, length = table_at(medium, mi, k)
                total += weight * tabulated.density(mf, psi_at, q_at, length, angle)
            else:
                total += weight * 2.0 * math.pi * math.sin(angle) * evaluate_component(
                    medium, mf, mi, k, math.cos(angle))
        out[i] = total
    return out
