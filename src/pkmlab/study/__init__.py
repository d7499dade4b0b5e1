"""Design studies: a typed study → design space → evaluators → optimiser → store → reports.

``pkmlab run STUDY.yaml`` loads a :class:`Study` (:func:`load_study`), drives
:func:`run_study` with a runner from :mod:`.runners`; :mod:`.report` turns the store into
tables, plots and exported designs.
"""

from .definition import Study
from .evaluators import evaluate_design, evaluate_mechanism
from .metrics import METRICS, Metric
from .report import pareto_mask, pareto_records, write_report
from .run import CandidateError, run_study
from .runners import DaskRunner, JoblibRunner, SerialRunner
from .spec import load_study, study_from_mapping, study_schema
from .store import Store

__all__ = ["Study", "load_study", "study_from_mapping", "study_schema", "run_study",
           "evaluate_design", "evaluate_mechanism", "CandidateError", "METRICS", "Metric",
           "Store", "SerialRunner", "JoblibRunner", "DaskRunner", "pareto_mask",
           "pareto_records", "write_report"]
