"""One entry point for the phase function of a layer: pick a component by its scattering weight,
then sample or evaluate it by model id."""
import math

import numpy as np
from numba import njit

from ..models import PHASE_HG, PHASE_QUADRATIC, PHASE_TABULATED
from . import henyey_greenstein, isotropic, quadratic, tabulated


@njit(error_model="numpy", cache=True)
def sample_component(model, params, tab_start, tab_len, tab_psi, tab_q, tab_cdf, u):
    if model == PHASE_HG:
        return henyey_greenstein.sample(params, u)
    if model == PHASE_TABULATED:
        return tabulated.sample(tab_psi, tab_q, tab_cdf, tab_start, tab_len, u)
    if model == PHASE_QUADRATIC:
        return quadratic.sample(params, u)
    return isotropic.sample(params, u)


@njit(error_model="numpy", cache=True)
def evaluate_component(model, params, tab_start, tab_len, tab_psi, tab_q, cos_psi):
    if model == PHASE_HG:
        return henyey_greenstein.evaluate(params, cos_psi)
    if model == PHASE_TABULATED:
        return tabulated.evaluate(tab_psi, tab_q, tab_start, tab_len, cos_psi)
    if model == PHASE_QUADRATIC:
        return quadratic.evaluate(params, cos_psi)
    return isotropic.evaluate(params, cos_psi)


@njit(error_model="numpy", cache=True, inline="always")
def component_params(sc, k):
    """The component's parameters as a tuple of floats: a row view of the 2-D array would cost
    a reference-count update per scattering event."""
    return (sc.comp_params[k, 0], sc.comp_params[k, 1])


@njit(error_model="numpy", cache=True, inline="always")
def pick_component(sc, layer, u):
    """The component of the layer's mixture that scatters, chosen with probability b_k / b."""
    first = sc.layer_comp_start[layer]
    count = sc.layer_comp_count[layer]
    k = first
    while k < first + count - 1 and u >= sc.comp_cumweight[k]:
        k += 1
    return k


@njit(error_model="numpy", cache=True, inline="always")
def sample_cos(sc, layer, u_pick, u):
    """cos(psi) from the layer's phase function; u_pick chooses the component of a mixture (it
    is ignored for a single component, so the caller need not draw it), u the angle."""
    if sc.layer_comp_count[layer] == 1:
        k = sc.layer_comp_start[layer]
    else:
        k = pick_component(sc, layer, u_pick)
    return sample_component(sc.comp_model[k], component_params(sc, k), sc.comp_tab_start[k],
                            sc.comp_tab_len[k], sc.tab_psi, sc.tab_q, sc.tab_cdf, u)


@njit(error_model="numpy", cache=True, inline="always")
def evaluate(sc, layer, cos_psi):
    """The layer's phase function p(cos_psi) in 1/sr: the b-weighted sum of its components."""
    first = sc.layer_comp_start[layer]
    total = 0.0
    previous = 0.0
    for k in range(first, first + sc.layer_comp_count[layer]):
        weight = sc.comp_cumweight[k] - previous
        previous = sc.comp_cumweight[k]
        total += weight * evaluate_component(sc.comp_model[k], component_params(sc, k),
                                             sc.comp_tab_start[k], sc.comp_tab_len[k],
                                             sc.tab_psi, sc.tab_q, cos_psi)
    return total


@njit(error_model="numpy", cache=True)
def layer_density(sc, layer, angles):
    """q(psi) = 2 pi p(psi) sin(psi) of the layer's phase function at each angle (rad), for
    tables built once per scene; tabulated components are read exactly, without the loss of
    precision of cos(psi) near 0."""
    out = np.empty(angles.shape[0])
    first = sc.layer_comp_start[layer]
    for i in range(angles.shape[0]):
        angle = angles[i]
        total = 0.0
        previous = 0.0
        for k in range(first, first + sc.layer_comp_count[layer]):
            weight = sc.comp_cumweight[k] - previous
            previous = sc.comp_cumweight[k]
            if sc.comp_model[k] == PHASE_TABULATED:
                total += weight * tabulated.density(sc.tab_psi, sc.tab_q, sc.comp_tab_start[k],
                                                    sc.comp_tab_len[k], angle)
            else:
                total += weight * 2.0 * math.pi * math.sin(angle) * evaluate_component(
                    sc.comp_model[k], component_params(sc, k), 0, 0, sc.tab_psi, sc.tab_q,
                    math.cos(angle))
        out[i] = total
    return out
