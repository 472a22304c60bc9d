"""The airfoil stage's speed-up (issue 15, "all characteristics of five sections in under
1 s"): the section table's CAD cut reused for the nominal profile gives the characteristics of
a fresh cut of the CAD, to the bit."""
import dataclasses
import unittest

from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_values as values
from tests.helpers import demo_nominal
from tests.test_airfoil_pipeline import Readings, _noisy, _stage


class NominalCutReused(unittest.TestCase):
    def test_the_tables_cut_gives_a_fresh_cuts_characteristics(self):
        nominal = demo_nominal()
        stage, table, result = _stage(nominal, _noisy(Readings.get(nominal)["sections"],
                                                      0.002, 3))
        planes = stage_mod.planes_of_table(table)
        self.assertTrue(all(p.cut_polylines for p in planes))
        fresh = stage_mod.run_stage(nominal, [dataclasses.replace(p, cut_polylines=None)
                                              for p in planes],
                                    stage_mod.Options(draws=0), result, table.span_axis)
        for a, b in zip(stage.blocks, fresh.blocks):
            self.assertEqual(values.flat(a["nominal"]), values.flat(b["nominal"]))
            self.assertEqual(values.flat(a["measured"]), values.flat(b["measured"]))


if __name__ == "__main__":
    unittest.main()
