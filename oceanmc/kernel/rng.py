"""The photon loop's random numbers: xoshiro256** (Blackman & Vigna, "Scrambled linear
pseudorandom number generators", ACM Trans. Math. Softw. 47(4), 36, 2021; reference C code at
https://prng.di.unimi.it/xoshiro256starstar.c), period 2^256 - 1, with its state in a uint64
array of 4 that the caller owns and passes down (one per batch).

Each batch's state is 256 bits from numpy's SeedSequence(seed, spawn_key=(batch,)): the whole
(seed, batch) pair goes into the hash, so distinct pairs have unrelated states (O'Neill's
SeedSequence design; numpy.random.SeedSequence), unlike the 32-bit seeds of Numba's global
Mersenne Twister used before, where seeds 510 and 898 gave one batch the same stream. The state
is plain data: a batch traced in several calls continues its stream exactly, and a checkpoint
stores it."""
import numpy as np

from .compile import hot

STATE_WORDS = 4
_TO_UNIT = 1.0 / 9007199254740992.0   # 2^-53


def batch_state(seed: int, batch: int, stream: int = 0) -> np.ndarray:
    """The generator state of batch `batch` of a run with seed `seed` (never all zero: the
    generator's one forbidden state, probability 2^-256); stream 1 is the batch's second
    stream, which inelastic emissions draw from (kernel/channels/inelastic.py)."""
    key = (int(batch),) if stream == 0 else (int(batch), int(stream))
    state = np.random.SeedSequence(int(seed), spawn_key=key).generate_state(
        STATE_WORDS, np.uint64)
    if not state.any():
        state[0] = 1
    return state


@hot
def uniform(rng):
    """A double in [0, 1): the top 53 bits of the next output (the reference's recommended
    conversion), advancing the state in place."""
    s0, s1, s2, s3 = rng[0], rng[1], rng[2], rng[3]
    x = s1 * np.uint64(5)
    out = ((x << np.uint64(7)) | (x >> np.uint64(57))) * np.uint64(9)
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    rng[0] = s0
    rng[1] = s1
    rng[2] = s2
    rng[3] = (s3 << np.uint64(45)) | (s3 >> np.uint64(19))
    return np.float64(out >> np.uint64(11)) * _TO_UNIT
