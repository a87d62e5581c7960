"""Scenario files: YAML in `scenarios/`, loaded and validated once into frozen dataclasses.

Every scenario is written in the world frame (z up, REP-103 SI units). A bad value is one
`ScenarioError` whose message names the file, the key, the value and the rule; the command line
turns it into a single line on stderr and exit code 2.

The package: `config` (the dataclasses), `reading` (a mapping read with checks), `vehicle`,
`parse` (a file's mapping -> Scenario), `limits` (what the bodies cannot be or the vehicles
cannot fly), `files` (names, paths, load/loads). Its names are
imported from here: `from multilift_sim import scenario as scenario_io; scenario_io.load(...)`.
"""
from multilift_sim.scenario.config import (  # noqa: F401
                                           FORMATION_GEOMETRIES, INPUT_SHAPERS,
                                           ControlConfig, EventConfig,
                                           FormationConfig, MissionConfig, MissionSegment,
                                           PayloadConfig, Scenario, ScenarioError, SensorConfig,
                                           SimulationConfig, UavConfig)
from multilift_sim.scenario.controllers import (FOLLOWER_CONTROLLERS,  # noqa: F401
                                                LEADER_CONTROLLERS, follower_controllers,
                                                leader_controllers)
from multilift_sim.scenario.files import (anchored, from_mapping, load, loads,  # noqa: F401
                                          read_yaml,
                                          resolve, scenario_dir)
from multilift_sim.scenario.vehicle import (INERTIA_SOURCES, SEED_INERTIA,  # noqa: F401
                                            VEHICLE_KEYS)
