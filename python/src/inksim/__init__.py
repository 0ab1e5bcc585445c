from .result import Result, open_result
from .study import Study, open_study
