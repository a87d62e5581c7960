"""The figures of `multilift plot` by concept (figures.py holds the registry and the command):

    scene       the formation's geometry at a time, from the bag and its scenario: where each
                cable ends (a rigid body's attach points), which cables were released, a rigid
                body's outline (its box's corners, its cylinder's axis and rims)
    views       the 3-D trajectories and the top view, drawn from the scene
    ropes       elastic ropes' stretch and tension (cable_model: elastic), winches' reeled
                lengths (uavs[i].winch)
    estimation  each UAV's estimated position against the truth in its 3-sigma band (an
                estimator, docs/estimation.md)
    rotors      collective thrust and rotor speeds (each rotor its colour and dash; the clipped
                strips at the limit they hit)
"""
