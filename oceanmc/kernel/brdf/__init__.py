"""Bottom BRDFs, one module each, in a local frame with the normal along +z. wi points from the
surface towards where the light came from, wo along the reflected travel direction (both with
z > 0). Each module has sample(params, wix, wiy, wiz, u1, u2) -> (wox, woy, woz, weight) with
weight = f cos(theta_o) / pdf (the directional-hemispherical reflectance for the analytic
samplers of Lambertian, Minnaert and the Lambertian + mirror mixture), evaluate(params, wi...,
wo...) -> f in 1/sr, and pdf(params, wi..., wo...) in 1/sr. Models without an analytic sampler
(Hapke, measured tables) have only evaluate(); general.py samples them from tables built once
per scene (scene/brdf_tables.py). dispatch.py picks the module by its integer id (names and ids:
oceanmc/registry.py); tables.py holds the compiled loops that build and check the tables (run
once per scene, never per ray)."""
