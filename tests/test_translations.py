"""The workbench's translation source (resources/translations/BladeInspect.ts) holds every text
the sources mark for translation, and is a well-formed Qt Linguist file."""
import os
import subprocess
import unittest
import xml.etree.ElementTree as ET

from tests.helpers import REPO

SCRIPT = os.path.join(REPO, "scripts", "update-translations")
TS = os.path.join(REPO, "resources", "translations", "BladeInspect.ts")


class TranslationSource(unittest.TestCase):
    def test_the_ts_file_is_up_to_date(self):
        done = subprocess.run([SCRIPT, "--check"], capture_output=True,
                              text=True, timeout=60)
        self.assertEqual(done.returncode, 0, done.stderr)

    def test_it_is_linguist_xml_with_the_command_texts(self):
        root = ET.parse(TS).getroot()
        self.assertEqual(root.tag, "TS")
        by_context = {c.findtext("name"): {m.findtext("source") for m in c.iter("message")}
                      for c in root.iter("context")}
        # Texts as the sources write them (InitGui.py, gui/commands.py, gui/taskpanels.py).
        for context, text in (("Workbench", "BladeInspect"),
                              ("BladeInspect_Register", "Register"),
                              ("BladeInspect", "Simulated rig")):
            self.assertIn(text, by_context.get(context, ()), context)
        for context in by_context.values():
            for message in context:
                self.assertTrue(message.strip())


if __name__ == "__main__":
    unittest.main()
