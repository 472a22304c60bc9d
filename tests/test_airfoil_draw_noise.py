"""The airfoil draws' sensor noise (inspection.airfoil._point_noise_model) against the
simulated sensor's own readings (rig.sensor.SensorModel.read): a reading errs along its beam
by sigma_beam(SNR), so the draws lay it there, not along the profile's normal."""
import dataclasses
import unittest

import numpy as np

from BladeInspect.inspection import airfoil
from BladeInspect.rig.sensor import SensorModel
from tests import inspection_fixtures as fx
from tests.test_worst_uncertainty import head_on_readings

READINGS = 4000


class DrawNoiseAlongTheBeam(unittest.TestCase):
    def test_against_the_sensors_readings(self):
        nominal = fx.demo_nominal()
        on, normal, angles, beams, pick, cos = head_on_readings(nominal)
        sensor = SensorModel()
        incidence = np.arccos(np.clip(cos, -1.0, 1.0))
        snr = sensor.snr(np.full(len(on), sensor.standoff), incidence)
        result = dataclasses.replace(
            fx.make_result(nominal, on, columns={"angle_deg": angles[pick]}), snr=snr)
        idx = np.arange(0, len(on), 60)
        sigma, spread, along, unit = airfoil._point_noise_model(result, idx, sensor, 0.003,
                                                                normal[idx])
        np.testing.assert_allclose(along, beams[pick][idx], atol=1e-9)
        rng = np.random.default_rng(3)
        d = np.full(READINGS, sensor.standoff)
        for j, i in enumerate(idx):
            reading, _ = sensor.read(d, np.full(READINGS, incidence[i]), rng)
            err = reading - d
            # the sensor's rare gross errors (0.1 mm and more) are the fit's to reject
            err = err[np.isfinite(err) & (np.abs(err) < 5.0 * sensor.accuracy)]
            with self.subTest(point=int(i), incidence_deg=float(np.degrees(incidence[i]))):
                self.assertAlmostEqual(spread[j], np.std(err), delta=0.05 * np.std(err))
                # the deviations' model is the normal part of that error
                self.assertAlmostEqual(sigma[j], np.std(err) * cos[i],
                                       delta=0.05 * np.std(err) * cos[i])
        x = unit(rng, 100000)
        self.assertAlmostEqual(float(np.std(x)), 1.0, delta=0.01)


if __name__ == "__main__":
    unittest.main()
