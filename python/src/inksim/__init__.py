from .result import Result, open_result
