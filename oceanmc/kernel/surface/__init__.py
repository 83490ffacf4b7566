"""The air-water surface models, one module each (flat Fresnel, index-matched), behind the BSDF
interface of dispatch.py."""
