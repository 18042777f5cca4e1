"""A part's argument types (compile/decorators.py ``part``, compile/parts.py): the tables the
layer above binds (compile/parts.py ``bind``), then numba scalars."""
PART_TABLES = ("model", "state", "workspace", "options")
PART_SCALARS = ("float64", "int64", "boolean")
PART_ARGS = PART_TABLES + PART_SCALARS
