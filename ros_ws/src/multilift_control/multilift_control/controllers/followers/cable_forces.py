"""Cable-force allocation (`formation.reorganize: cable_forces`, issue 35 item 3, three UAVs and
a point payload): each tick the share of the payload's apparent weight each cable should carry
so that every UAV flies at the same share of its largest thrust (the least effort under the
thrust limits; `laws.reorganize.load_shares`, closed form), and the places where level cables
pull those forces (`allocated_places`: the triangle of forces); the followers' offsets move
there at `formation.max_offset_rate` within the spacing and spread limits and the followers
fly the seed's virtual-constraint law to them. Its arrays are `thrust_margin`'s."""
from __future__ import annotations

from multilift_control.controllers.followers import thrust_margin
from multilift_control.laws import jit
from multilift_control.laws.follower import follower_update, formation_terms
from multilift_control.laws.reorganize import allocate

NAME = 'cable_forces'
KEYS = ()  # its keys are the formation section's
arrays = thrust_margin.arrays
shared = thrust_margin.shared


@jit
def answer(constants, memory, cascade, mixer, index, t, states, vectors, masses, rows,
           targets, law_p, law_q, terms, speeds, saturated, setpoint, errors, rates):
    """Follower `index`'s tick at t [s]: the allocation's step (`laws.reorganize.allocate`),
    then the seed follower's tick (`follower_update`) to the moved targets; writes as
    `virtual_constraints.answer` and returns the collective thrust asked [N]."""
    kept = allocate(constants, memory, t, masses, rows, targets, vectors)
    own_terms = formation_terms(constants, masses, rows, kept, states, vectors)
    s, sat, attitude, thrust, own_errors, own_rates = follower_update(
        constants, masses, rows, kept, law_p, law_q, index, memory, t, states, vectors,
        own_terms, cascade, mixer)
    for k in range(s.shape[0]):
        speeds[k] = s[k]
        saturated[k] = sat[k]
    for k in range(3):
        setpoint[k] = attitude[k]
    for k in range(own_errors.shape[0]):
        errors[k] = own_errors[k]
        rates[k] = own_rates[k]
    return thrust
