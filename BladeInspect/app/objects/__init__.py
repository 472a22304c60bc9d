"""BladeInspect's document objects: FeaturePython proxies that keep each stage's output in the
document, so it is saved in the .FCStd and recomputed when an input changes. One module per
object, as Fem's femobjects:

  demo_blade.DemoBlade / cad_model.CadModel   the nominal (Part shape, face roles)
  measurement.Measurement        measured points (double precision) + SNR + extra columns
  reconstruction.Reconstruction  section curves and lofted surfaces of a measurement
  registration.Registration      pose of a measurement on a nominal, statistics, uncertainty,
                                 deviations
  deviation_map.DeviationMap     the registered points coloured by deviation, with a legend

base.py holds what they share (the Proxy class, properties, signatures, building); nominal.py
the pipeline's Nominal of a shape; section_profiles.py the section analysis's profiles.

The make_* functions build them from plain pipeline data; the headless report writer and the GUI
commands use the same functions, through this package (`objects.make_registration(...)`), which
also names them in the console lines a macro replays. Long computations run in the GUI commands
with progress and cancel; an object's execute() repeats a stage only when its inputs really
changed (an input signature is stored), so opening a document or recomputing is cheap.

A document records each proxy's module and class name and imports them when it opens; a
document that names this package (`BladeInspect.app.objects`) finds every class here under its
own name.

No GUI imports here: the gui layer registers a hook (set_view_provider_hook) that gives new and
restored objects their view providers when FreeCAD.GuiUp.
"""

from .base import (HIDDEN, READ_ONLY, Proxy, add_property, add_table, attach_view, building,
                   check_recomputed, file_signature, find_objects, finish, points_kernel,
                   proxy_type, set_view_provider_hook, shape_signature, signature)
from .cad_model import CadModel, make_cad_model
from .demo_blade import DemoBlade, make_demo_blade
from .deviation_map import DeviationMap, make_deviation_map
from .measurement import Measurement, make_measurement, pointset_of, store_pointset
from .nominal import nominal_of, roles_from_map, roles_to_map
from .reconstruction import Reconstruction, make_reconstruction, store_reconstruction
from .registration import (Registration, make_registration, matrix_array, registration_points,
                           registration_result, store_registration)
from .section_profiles import make_section_profiles

__all__ = [
    "HIDDEN", "READ_ONLY", "Proxy", "add_property", "add_table", "attach_view", "building",
    "check_recomputed", "file_signature", "find_objects", "finish", "points_kernel",
    "proxy_type", "set_view_provider_hook", "shape_signature", "signature",
    "CadModel", "make_cad_model", "DemoBlade", "make_demo_blade", "DeviationMap",
    "make_deviation_map", "Measurement", "make_measurement", "pointset_of", "store_pointset",
    "nominal_of", "roles_from_map", "roles_to_map", "Reconstruction", "make_reconstruction",
    "store_reconstruction", "Registration", "make_registration", "matrix_array",
    "registration_points", "registration_result", "store_registration",
    "make_section_profiles"]
