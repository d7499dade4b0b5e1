"""Design studies: design variables → candidate evaluation → optimiser → store → reports.

``pkmlab run STUDY.yaml`` drives :func:`run.run_study` with a runner from :mod:`.runners`;
:mod:`.report` turns the store into tables, plots and exported designs.
"""

from .evaluate import candidate_mapping, evaluate_candidate
from .report import pareto_mask, pareto_records, write_report
from .run import run_study
from .runners import DaskRunner, JoblibRunner, SerialRunner
from .store import Store

__all__ = ["run_study", "evaluate_candidate", "candidate_mapping", "Store", "SerialRunner",
           "JoblibRunner", "DaskRunner", "pareto_mask", "pareto_records", "write_report"]
