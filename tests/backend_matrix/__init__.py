"""The backend matrix: every public callable of rigidkit under every transform.

``examples.py`` holds one example call per public callable (and says which argument
to batch and to differentiate, or why a transform cannot apply); ``cells.py`` runs one
example under one transform against NumPy and finite differences; ``status.py``
declares the cells known to fail, with the reason; ``test_matrix.py`` runs them and
proves that the registry covers the public API; ``table.py`` writes
``docs/backends.md`` from the declarations (``python -m tests.backend_matrix.table``).
"""
