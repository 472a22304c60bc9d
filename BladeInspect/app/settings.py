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

# name: (kind "float" or "int", default, label, unit, minimum, maximum)
SETTINGS = {
    "StandoffMm": ("float", _SENSOR.standoff, "Sensor standoff z_s", "mm", 1.0, 500.0),
    "WorkingRangeMm": ("float", _SENSOR.half_range, "Sensor working range +-delta", "mm", 0.1,
                       100.0),
    "EpsilonMm": ("float", _SCAN.epsilon, "Rescan stop criterion epsilon", "mm", 0.01, 50.0),
    "SensorAccuracyMm": ("float", _SENSOR.accuracy, "Sensor accuracy", "mm", 0.0, 1.0),
    "PointsPerSecond": ("float", _SENSOR.rate_hz, "Sensor rate", "points/s", 1.0, 1e6),
    "Sections": ("int", _SCAN.n_sections, "Sections per scan", "", 1, 200),
    "SectionSpacingMm": ("float", 0.0, "Section spacing (0 = spread over the span)", "mm", 0.0,
                         1000.0),
    "PointSpacingMm": ("float", _SCAN.point_spacing, "Point spacing along a section", "mm",
                       0.005, 10.0),
    "Sides": ("int", _SCAN.sides, "Sides scanned (2 = the part turned over)", "", 1, 2),
    "ToleranceMm": ("float", PROFILE_TOLERANCE_MM, "Profile tolerance", "mm", 0.0001, 10.0),
    "ColourLimitMm": ("float", 0.0, "Colour map limit (0 = the tolerance)", "mm", 0.0, 10.0),
    "Seed": ("int", 0, "Random seed (simulated rig, registration)", "", 0, 2 ** 31 - 1),
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
