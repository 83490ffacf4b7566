"""No interface (surface model `none`): water and air have the same index, light crosses
unchanged and nothing is reflected."""
from ..compile import kernel


@kernel
def split(surface, ux, uy, uz):
    return 0.0, ux, uy, -uz, ux, uy, uz


@kernel
def transmittance(surface, mu):
    return 1.0
