"""The estimation figure (issue 33 item 6): a bag of `twin_lift_realistic` carries each UAV's
estimate with its pose covariance; the estimated positions less the truth lie inside their
3-sigma band at about 99.7 % of the samples (a Gaussian's share: the filter is consistent, as
its NEES shows), and `multilift plot` draws them (estimation.png) only where there are
estimates."""
from __future__ import annotations

import dataclasses

import numpy as np

from multilift_sim import scenario as scenario_io
from multilift_tools.bagdata import load_run
from multilift_tools.figures import plot_main
from multilift_tools.headless_bag import record_headless
from multilift_tools.plots.estimation import estimate_errors, lacks_estimates


def test_the_estimates_lie_in_their_3_sigma_band_and_are_drawn(tmp_path):
    base = scenario_io.load('twin_lift_realistic')
    scenario = dataclasses.replace(base, simulation=dataclasses.replace(base.simulation,
                                                                        duration=20.0))
    record_headless(scenario, tmp_path / 'bag')
    run = load_run(tmp_path / 'bag')
    for i in (1, 2):
        t, error, sigma = estimate_errors(run, i)
        assert len(t) == 2001 and np.all(sigma > 0.0)
        inside = np.mean(np.abs(error) <= 3.0 * sigma)
        assert 0.98 <= inside < 1.0                  # 99.7 % for a Gaussian error
        assert np.sqrt(np.mean(error ** 2)) < 1e-3   # sub-millimetre (1 mm mocap fused)
    t, error, sigma = estimate_errors(run, 0)  # the payload's (/payload/estimate)
    assert len(t) == 2001 and np.all(sigma > 0.0)
    assert np.mean(np.abs(error) <= 3.0 * sigma) >= 0.97  # 99 % over 120 s: docs/estimation.md
    assert np.sqrt(np.mean(error ** 2)) < 0.02  # centimetres (the bound: 0.2 m)
    assert plot_main([str(tmp_path / 'bag'), '--out', str(tmp_path / 'plots')]) == 0
    assert (tmp_path / 'plots' / 'estimation.png').stat().st_size > 0
    record_headless(scenario_io.load('twin_lift').with_duration(1.0), tmp_path / 'exact')
    assert lacks_estimates(load_run(tmp_path / 'exact'))


def test_the_foxglove_layout_shows_each_estimate_beside_the_truth_only_with_an_estimator():
    from multilift_tools.foxglove.layout import layout
    config = layout(scenario_io.load('twin_lift_realistic'))['configById']
    for i in (1, 2):
        paths = [s['value'] for s in config[f'Plot!estimate{i}']['paths']]
        assert paths == [f'/uav{i}/{topic}.pose.pose.position.{axis}'
                         for topic in ('estimate', 'odom') for axis in 'xyz']
    paths = [s['value'] for s in config['Plot!payload_estimate']['paths']]
    assert paths == [f'{topic}.pose.pose.position.{axis}'
                     for topic in ('/payload/estimate', '/payload/odom') for axis in 'xyz']
    assert not any(key.startswith(('Plot!estimate', 'Plot!payload_estimate'))
                   for key in layout(scenario_io.load('twin_lift'))['configById'])
