"""The workbench's settings in FreeCAD's parameters
(User parameter:BaseApp/Preferences/Mod/BladeInspect), read by the GUI's preferences page, its
commands and the document objects alike. The defaults are the sensor model's (paper Table 1),
the scan strategy's and the contracts' own (docs/contracts.md)."""
import FreeCAD

from ..core.contracts import PROFILE_TOLERANCE_MM
from ..measurement.strategy import ScanOptions
from ..rig.sensor import SensorModel

_SENSOR = SensorModel()
_SCAN = ScanOptions()

PARAM_PATH = "User parameter:BaseApp/Preferences/Mod/BladeInspect"

# name: (kind "float" or "int", default, unit, minimum, maximum, decimals shown). Their labels,
# groups and tooltips are the preferences page's (gui.preferences).
SETTINGS = {
    "StandoffMm": ("float", _SENSOR.standoff, "mm", 1.0, 500.0, 2),
    "WorkingRangeMm": ("float", _SENSOR.half_range, "mm", 0.1, 100.0, 2),
    "SensorAccuracyMm": ("float", _SENSOR.accuracy, "mm", 0.0, 1.0, 4),
    "PointsPerSecond": ("float", _SENSOR.rate_hz, "points/s", 1.0, 1e6, 0),
    "EpsilonMm": ("float", _SCAN.epsilon, "mm", 0.01, 50.0, 2),
    "Sections": ("int", _SCAN.n_sections, "", 1, 200, 0),
    "SectionSpacingMm": ("float", 0.0, "mm", 0.0, 1000.0, 2),
    "PointSpacingMm": ("float", _SCAN.point_spacing, "mm", 0.005, 10.0, 3),
    "Sides": ("int", _SCAN.sides, "", 1, 2, 0),
    "ToleranceMm": ("float", PROFILE_TOLERANCE_MM, "mm", 0.0001, 10.0, 4),
    "ColourLimitMm": ("float", 0.0, "mm", 0.0, 10.0, 4),
    "Seed": ("int", 0, "", 0, 2 ** 31 - 1, 0),
}


def _group():
    return FreeCAD.ParamGet(PARAM_PATH)


def value(name):
    kind, default = SETTINGS[name][:2]
    group = _group()
    if kind == "float":
        return group.GetFloat(name, default)
    return group.GetInt(name, default)


def store(name, new_value):
    kind = SETTINGS[name][0]
    group = _group()
    if kind == "float":
        group.SetFloat(name, float(new_value))
    else:
        group.SetInt(name, int(new_value))


def colour_limit():
    """The deviation at which the colour map saturates: its own setting, else the tolerance."""
    limit = value("ColourLimitMm")
    return limit if limit > 0 else value("ToleranceMm")


def sensor_model():
    """The rig's sensor as the preferences describe it (rig.sensor.SensorModel)."""
    from ..rig.sensor import SensorModel
    return SensorModel(standoff=value("StandoffMm"), half_range=value("WorkingRangeMm"),
                       accuracy=value("SensorAccuracyMm"), rate_hz=value("PointsPerSecond"))
