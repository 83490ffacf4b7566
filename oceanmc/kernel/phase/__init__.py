"""Phase functions, one module each: sample(params, u) -> cos(psi) and evaluate(params, cos_psi)
-> p in 1/sr, with params a tuple of floats (normalised: 2 pi integral of p d(cos psi) = 1). The azimuth of scattering is
uniform for all of them. dispatch.py picks the module by its integer id."""
