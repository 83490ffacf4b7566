"""Bottom BRDFs, one module each, in a local frame with the normal along +z. wi points from the
surface towards where the light came from, wo along the reflected travel direction (both with
z > 0). Each module has sample(params, wix, wiy, wiz, u1, u2) -> (wox, woy, woz, weight) with
weight = f cos(theta_o) / pdf (the directional-hemispherical reflectance for the analytic
samplers here), evaluate(params, wi..., wo...) -> f in 1/sr, and pdf(params, wi..., wo...) in 1/sr.
dispatch.py picks the module by its integer id."""
