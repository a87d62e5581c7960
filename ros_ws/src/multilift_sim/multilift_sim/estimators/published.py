"""What every estimator keeps first in one UAV's memory: its estimate as /uav{i}/estimate
(nav_msgs/Odometry, frame world, child uav{i}) carries it, in the message's order, written at
every tick it estimates (the engine's record and the simulator's snapshot copy it out)."""

ESTIMATE_POSITION = 0           # p [m], world (3)
ESTIMATE_ORIENTATION = 3        # (x, y, z, w) body -> world (4)
ESTIMATE_POSE_COVARIANCE = 7    # (x, y, z, rotation about world x, y, z), row by row (36)
ESTIMATE_LINEAR = 43            # velocity [m/s], body FLU (3)
ESTIMATE_ANGULAR = 46           # body rates [rad/s], body FLU (3)
ESTIMATE_TWIST_COVARIANCE = 49  # (linear, angular), body, row by row (36)
ESTIMATE_COLUMNS = 85
COVARIANCE_SIDE = 6             # each covariance: 6 x 6, row by row (nav_msgs/Odometry's)


def payload_read(estimate):
    """(position [m], velocity [m/s]) (3,) each, world, of a point payload's estimate as
    /payload/estimate carries it (its frame has the world's axes): what the controllers read
    of the payload with a payload estimator (payload_estimators); arrays (..., >=
    ESTIMATE_COLUMNS) give (..., 3)."""
    return (estimate[..., ESTIMATE_POSITION:ESTIMATE_POSITION + 3],
            estimate[..., ESTIMATE_LINEAR:ESTIMATE_LINEAR + 3])
