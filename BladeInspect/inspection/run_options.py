"""The options one run shares, as one object: built once by the command line (cli.py) or by a
GUI action (app.actions) and handed down to `register`, `report`, `batch` and `inspect`
(pipeline.run_register, report.run_report, batch.run_batch, closed_loop.run_inspect) and to
the functions they call.

``RunOptions`` holds what changes an answer and is shared by the commands: the seed, the
profile tolerance, the section heights, the CMM file, the faces to flip, the fit
(inspection.fitting.FitChoice), the measurement model (inspection.uncertainty), the airfoil
options (inspection.airfoil_stage.Options; None: no airfoil characteristics) and the rig file.
``LoopOptions`` holds what only the `inspect` loop uses; ``RegisterOptions`` what
pipeline.register needs besides the points and the seed.
"""

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Optional

from ..core import contracts
from ..measurement.planning import DEFAULT_EDGE_RADIUS_SIGMA_MM

# The standoff criterion of the planned scan (mm): a reading further than this from the
# planned standoff means the part is not where the registration put it.
EPSILON_MM = 2.0


@dataclass(frozen=True)
class LoopOptions:
    """The `inspect` loop's own options. ``rig_spec``: sim or serial:PORT; ``complete``: the
    whole blade rastered every ``pitch`` mm (--complete, --pitch); ``epsilon``: the standoff
    criterion (mm); ``scan_options``: the blind scan's (measurement.scan.scan_to_dir, e.g.
    n_sections); ``resume``: continue the interrupted inspection in the output folder
    (``scan_options`` None takes the interrupted run's); ``edge_radius_sigma_mm``: the planned
    sections' edge-density target (measurement.planning; None, 0 or "off": the rule off)."""
    rig_spec: str = "sim"
    complete: bool = False
    pitch: float = 0.1
    epsilon: float = EPSILON_MM
    scan_options: Optional[dict] = None
    resume: bool = False
    edge_radius_sigma_mm: Any = DEFAULT_EDGE_RADIUS_SIGMA_MM


@dataclass(frozen=True)
class RegisterOptions:
    """pipeline.register's choices besides the points and the seed: ``allow_mismatch`` keeps
    the result of points that do not fit the CAD (with the warning), ``tolerance`` the profile
    tolerance the fit rule allows, ``cad_source`` names the CAD in messages, ``fit_choice``
    (inspection.fitting.FitChoice) is applied after the ICP, ``weights`` the fine fit's
    ("snr", "sensor" or None for the default, which also takes ``fit_choice.weights``)."""
    allow_mismatch: bool = False
    tolerance: float = contracts.PROFILE_TOLERANCE_MM
    cad_source: Optional[str] = None
    fit_choice: Any = None
    weights: Optional[str] = None


@dataclass(frozen=True)
class RunOptions:
    """What a run of `register`, `report`, `batch` or `inspect` is made with besides its
    input and output files. ``cmm``: a CMM points file (sections.read_cmm); ``flip_faces``:
    CAD faces whose outward side is reversed (--flip-face, cad.orient); ``fit_choice``:
    inspection.fitting.FitChoice (None: least squares and ISO 14253-1);
    ``measurement_model``: inspection.uncertainty.MeasurementModel (None: the default);
    ``airfoil``: inspection.airfoil_stage.Options (None: no airfoil characteristics);
    ``rig_file``: RIG.json of the rig's kinematics (None: the nominal rig); ``loop``: the
    `inspect` loop's own options."""
    seed: int = 0
    tolerance: float = contracts.PROFILE_TOLERANCE_MM
    section_heights: Any = contracts.SECTION_HEIGHTS_PCT
    cmm: Optional[str] = None
    flip_faces: Any = ()
    allow_mismatch: bool = False
    fit_choice: Any = None
    measurement_model: Any = None
    airfoil: Any = None
    rig_file: Optional[str] = None
    loop: LoopOptions = field(default_factory=LoopOptions)

    def replace(self, **changes):
        """A copy with ``changes``; the `inspect` loop's fields (LoopOptions) may be given
        here too."""
        loop_names = {f.name for f in dataclasses.fields(LoopOptions)}
        loop = {k: changes.pop(k) for k in list(changes) if k in loop_names}
        if loop:
            changes["loop"] = dataclasses.replace(changes.get("loop", self.loop), **loop)
        return dataclasses.replace(self, **changes)

    @classmethod
    def of(cls, **options):
        """RunOptions from keywords of RunOptions and LoopOptions together."""
        return cls().replace(**options)

    def register_options(self, cad_source):
        """pipeline.register's options for this run's points against the CAD ``cad_source``."""
        return RegisterOptions(allow_mismatch=self.allow_mismatch, tolerance=self.tolerance,
                               cad_source=cad_source,
                               weights=getattr(self.fit_choice, "weights", None))


@dataclass(frozen=True)
class ReportSources:
    """What a report is made from besides the registration (report.write_result_report):
    ``cad_path`` the nominal's CAD file (None: the demo blade), ``cmm_data`` the CMM's table
    (sections.read_cmm; None: none), ``batch_inputs`` what a batch made the file from
    (inspection.batch.inputs_record; None: not a batch's), ``planned`` an inspection's
    sections (inspection.planned_sections.PlannedSections; None: the sections the points'
    section column or the section heights give)."""
    cad_path: Optional[str] = None
    cmm_data: Any = None
    batch_inputs: Optional[dict] = None
    planned: Any = None


@dataclass(frozen=True)
class FineOptions:
    """pipeline.fine_register's limits and start: ``time_limit_s`` for both of its ICP runs
    (None: pipeline.FINE_TIME_LIMIT_S), ``full_distance`` the TrackedDistance of all the
    points (None: one of its own), ``systematic_mm`` the sensor's stated accuracy (None: the
    default sensor's, inspection.checks.SENSOR_ACCURACY_MM)."""
    time_limit_s: Optional[float] = None
    full_distance: Any = None
    systematic_mm: Optional[float] = None
