"""Every characteristic a section's airfoil block holds has a display name and a unit
(inspection.characteristic_names), so that a field added to the block without a name fails
here instead of showing as its JSON key in the report and the workbench; the same for Table 2's
columns and the fit-sensitivity rows. The unit is checked against the field name's own suffix
(the contract's naming: _mm, _mm2, _deg, _pct), not against the table."""
import types
import unittest

from BladeInspect.inspection import airfoil_stage as stage_mod
from BladeInspect.inspection import airfoil_values as values
from BladeInspect.inspection import characteristic_names as names
from BladeInspect.inspection import report
from tests.helpers import demo_nominal

# The unit each contract suffix stands for.
SUFFIX_UNITS = (("_mm2", "mm\u00b2"), ("_mm", "mm"), ("_deg", "\u00b0"), ("_pct", "% chord"))
# Fields of a block's values that are not characteristics (they define one).
DEFINITIONS = {"chord_method", "edge_offsets_mm"}


def _suffix_unit(key):
    base = key.split("[", 1)[0]
    return next(unit for suffix, unit in SUFFIX_UNITS if base.endswith(suffix))


class AirfoilBlockNames(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        nominal = demo_nominal()
        planes = stage_mod.nominal_planes(nominal, [50.0])
        stage = stage_mod.run_stage(nominal, planes, stage_mod.Options(draws=0))
        cls.values = stage.sections[0].block["nominal"]
        cls.keys = list(values.flat(cls.values))

    def test_every_numeric_field_of_the_block_is_a_named_characteristic(self):
        for field, value in self.values.items():
            if field in DEFINITIONS:
                continue
            numeric = isinstance(value, (int, float)) or (
                isinstance(value, list) and all(isinstance(v, (int, float)) for v in value))
            if numeric:
                self.assertIn(field, names.NAMES, "no display name for %r" % field)

    def test_every_key_has_a_name_unit_and_meaning(self):
        self.assertGreater(len(self.keys), 20)
        for key in self.keys:
            name = names.display_name(key, self.values)
            self.assertNotEqual(name, key)
            self.assertNotIn("_", name, key)
            self.assertNotIn("%", name, key)      # every template filled
            self.assertEqual(names.unit(key), _suffix_unit(key), key)
            self.assertIn(key, names.meaning(key))

    def test_names_tell_the_keys_apart(self):
        shown = [names.display_name(k, self.values) for k in self.keys]
        self.assertEqual(len(set(shown)), len(shown), shown)

    def test_names_follow_the_run(self):
        self.assertEqual(names.display_name("chord_mm", self.values), "Chord (nose-tail)")
        self.assertEqual(names.display_name("chord_mm", {"chord_method": "caliper"}),
                         "Chord (caliper)")
        offsets = self.values["edge_offsets_mm"]
        self.assertEqual(names.display_name("te_thickness_mm[%d]" % (len(offsets) - 1),
                                            self.values),
                         "TE thickness at %g mm" % offsets[-1])

    def test_every_field_the_stage_knows_is_named(self):
        for field in stage_mod.CHARACTERISTICS:
            self.assertIn(field, names.NAMES)
        for field in stage_mod.LISTS:
            self.assertTrue(field in names.EDGE_FIELDS or field in names.AXES, field)


class SensitivityRows(unittest.TestCase):
    """fit_sensitivity's rows are named "section L worst deviation", "part worst deviation"
    (inspection.fitting) and "section L key" (inspection.airfoil_verdicts.add_to_sensitivity)."""

    def test_rows_split_into_section_and_characteristic(self):
        for row, parts in (({"characteristic": "section 2 worst deviation"}, ("2", None)),
                           ({"characteristic": "part worst deviation"}, (None, None)),
                           ({"characteristic": "section root 1 le_thickness_mm[1]",
                             "airfoil": True}, ("root 1", "le_thickness_mm[1]"))):
            self.assertEqual(names.sensitivity_row_parts(row), parts)

    def test_row_names(self):
        definitions = {"chord_method": "tangent", "edge_offsets_mm": [0.25, 0.5]}
        self.assertEqual(names.sensitivity_row_name(
            {"characteristic": "section 3 le_thickness_mm[1]", "airfoil": True},
            values=definitions), "Section 3: LE thickness at 0.5 mm")
        self.assertEqual(names.sensitivity_row_name(
            {"characteristic": "section 3 chord_mm", "airfoil": True}, values=definitions),
            "Section 3: Chord (tangent)")
        self.assertEqual(names.sensitivity_row_name({"characteristic": "part worst deviation"}),
                         "Part: Worst deviation")


class VerdictLines(unittest.TestCase):
    """The airfoil verdict's line names the failed and not-proven characteristics as the
    tables do; result.json's summary (field names) is left as the stage wrote it."""
    DEFINITIONS = {"chord_method": "caliper", "edge_offsets_mm": [0.5, 1.0, 2.0]}
    BLOCKS = [{"label": "2", "nominal": DEFINITIONS}, {"label": "root 1", "nominal": {}}]

    def test_entries(self):
        for entry, text in (("section 2: le_thickness_mm[1]", "Section 2: LE thickness at 1 mm"),
                            ("section 2: chord_mm", "Section 2: Chord (caliper)"),
                            ("section root 1: te_radius_mm (not measured)",
                             "Section root 1: TE radius (not measured)"),
                            ("section 2: stagger_deg", "Section 2: Stagger angle (caliper)"),
                            ("section root 1: stagger_deg", "Section root 1: Stagger angle"),
                            ("something else", "something else")):
            values = {b["label"]: b["nominal"] for b in self.BLOCKS}
            self.assertEqual(names.verdict_entry_name(entry, values), text)

    def test_lines(self):
        fail = {"n_judged": 7, "failed": ["section 2: le_thickness_mm[1]",
                                          "section root 1: te_radius_mm (not measured)"],
                "not_proven": ["section 2: stagger_deg"],
                "summary": "airfoil: FAIL 2 of 7: section 2: le_thickness_mm[1]; section root 1: "
                           "te_radius_mm (not measured)"}
        self.assertEqual(names.airfoil_verdict_text(fail, self.BLOCKS),
                         "Airfoil: FAIL, 2 of 7 characteristics: Section 2: LE thickness at 1 mm; "
                         "Section root 1: TE radius (not measured)")
        unproven = {"n_judged": 3, "failed": [], "not_proven": ["section 2: stagger_deg"]}
        self.assertEqual(names.airfoil_verdict_text(unproven, self.BLOCKS),
                         "Airfoil: NOT PROVEN, 1 of 3 characteristics: Section 2: Stagger angle "
                         "(caliper)")
        self.assertEqual(names.airfoil_verdict_text({"n_judged": 3, "failed": [],
                                                     "not_proven": []}),
                         "Airfoil: PASS (3 characteristics)")
        self.assertEqual(names.airfoil_verdict_text({"n_judged": 0, "failed": [],
                                                     "not_proven": []}),
                         "Airfoil: no characteristic toleranced")
        part = "FAIL: %s; profile PASS: within +-0.040 mm" % fail["summary"]
        self.assertEqual(names.part_summary_text(part, fail, self.BLOCKS),
                         "FAIL: Airfoil: FAIL, 2 of 7 characteristics: Section 2: LE thickness "
                         "at 1 mm; Section root 1: TE radius (not measured); profile PASS: "
                         "within +-0.040 mm")
        self.assertEqual(names.part_summary_text("PASS: within +-0.040 mm", None),
                         "PASS: within +-0.040 mm")

    def test_the_stage_writes_what_the_line_reads(self):
        """inspection.airfoil_verdicts.stage_verdict's entries and summary, as the stage writes
        them, read back in display names."""
        verdict = stage_mod.stage_verdict(
            [types.SimpleNamespace(block={"verdicts": {"a": "fail", "b": "pass"}})],
            ["section 2: area_mm2"], [])
        self.assertEqual(verdict["summary"], "airfoil: FAIL 1 of 2: section 2: area_mm2")
        self.assertEqual(names.airfoil_verdict_text(verdict),
                         "Airfoil: FAIL, 1 of 2 characteristics: Section 2: Section area")


class SectionTableColumns(unittest.TestCase):
    def test_every_table_2_column_has_a_short_header_and_a_meaning(self):
        for cmm in (None, "cmm.csv"):
            table = types.SimpleNamespace(cmm_source=cmm, within=0.025, sections=[])
            header, _ = report.section_rows(table)
            for column in header:
                short, meaning = names.section_column(column)
                self.assertNotEqual(meaning, column, column)
                # no header line much longer than its widest number ("0.0000", "100.00")
                self.assertLessEqual(max(len(line) for line in short.split("\n")), 10, short)
        short, meaning = names.section_column("0.025 mm (%)")
        self.assertIn("0.025", short)
        self.assertIn("0.025", meaning)


if __name__ == "__main__":
    unittest.main()
