"""inspection.FCStd: the inspection as a FreeCAD document, written headless.

The document holds the workbench's own objects (app.objects), so it opens in the
workbench exactly as if the inspection had been done there: the nominal (DemoBlade or
CadModel), the Measurement (the points as read, in their own frame), the Registration holding
the result (linked to both, so it re-registers only if one of them changes), the DeviationMap
(a Points::FeaturePython whose App::PropertyColorList "Color" has one colour per point, from
core.colourmap) and the nominal section profiles. The verdict is stored beside the section
profiles. Nothing is recomputed on opening: each object carries the signature of its inputs.

The pipeline functions that write inspection.FCStd (inspection.report.run_report,
inspection.closed_loop.run_inspect, inspection.batch.run_batch) sit below app/ and take
``write_inspection_document`` as their ``document`` argument from the callers above them (the
CLI, the GUI, tests).
"""

import json
import os

import FreeCAD
import numpy as np

from ..core import transforms as tf
from ..core.contracts import PROFILE_TOLERANCE_MM
from ..core.errors import InputError
from ..core.pointio import PointSet
from ..cad.load import builtin_cad
from . import objects


def _measured_pointset(result):
    """The points as they were read (input frame), with SNR and extra columns."""
    xyz = tf.apply_transform(tf.invert_transform(np.asarray(result.measured_to_cad)),
                             np.asarray(result.points_cad, dtype=float))
    return PointSet(xyz=xyz, snr=result.snr, columns=dict(result.columns),
                    n_rows_skipped=int(result.n_rows_skipped), source=result.source)


def write_inspection_document(path, nominal, result, sections, tolerance=PROFILE_TOLERANCE_MM,
                              verdict=None, cad_path=None, name="Inspection"):
    """Save the inspection document at ``path`` (.FCStd) and close it. ``cad_path`` is the CAD
    file the nominal came from (None or a cad.load.BUILTIN_CADS name: the built-in demo blade).
    Returns the path."""
    if not str(path).lower().endswith(".fcstd"):
        raise InputError("%s: an inspection document must be an .FCStd file" % path)
    # hidden: when the GUI is up (a report run from the workbench) no 3D view opens for it
    doc = FreeCAD.newDocument(name, hidden=True)
    try:
        builtin = builtin_cad(cad_path)
        if builtin is not None:
            cad = objects.make_demo_blade(doc, **builtin)
        else:
            cad = objects.make_cad_model(doc, os.path.abspath(cad_path))
        measurement = objects.make_measurement(doc, _measured_pointset(result),
                                               source_file=_existing(result.source))
        registration = objects.make_registration(doc, result, measurement=measurement,
                                                 nominal=cad)
        deviation_map = objects.make_deviation_map(doc, registration, tolerance)
        deviation_map.Label = "Deviations (colour +-%.3f mm)" % tolerance
        if any(s.profile is not None and s.profile.polylines for s in sections.sections):
            profiles = objects.make_section_profiles(doc, sections, registration=registration)
            profiles.addProperty("App::PropertyString", "SectionTableJson", "Sections",
                                 "The section table (Table 2) as in result.json")
            profiles.SectionTableJson = json.dumps(sections.to_json())
            if verdict is not None:
                profiles.addProperty("App::PropertyString", "Verdict", "Verdict",
                                     "Pass/fail against the profile tolerance")
                profiles.Verdict = verdict["summary"]
                profiles.addProperty("App::PropertyString", "VerdictJson", "Verdict",
                                     "The verdict as in result.json")
                profiles.VerdictJson = json.dumps(verdict)
        # every object was built from its inputs just now: nothing to recompute on opening
        for obj in doc.Objects:
            obj.purgeTouched()
        doc.saveAs(os.path.abspath(path))
    finally:
        FreeCAD.closeDocument(doc.Name)
    return path


def _existing(path):
    # A Measurement re-reads its source file when that changes; a source that is not a file
    # (a synthetic cloud) is not linked.
    return path if path and os.path.isfile(path) else ""
