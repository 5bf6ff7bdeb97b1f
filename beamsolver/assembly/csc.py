"""Square ``scipy.sparse.csc_matrix`` objects of canonical patterns without scipy's constructor checks.

The tangent is built once or twice per Newton iteration from arrays whose pattern is canonical by
construction (sorted, unique int32 row indices per column: ``System``'s element pattern and the
union patterns of ``extra_pattern``); scipy's constructor checks them again, which costs more than
a small model's factorisation.  ``canonical_csc`` sets the same attributes directly where that
builds what the constructor builds (checked once at import), else calls the constructor.
"""
import numpy as np
import scipy.sparse as sp

__all__ = ["canonical_csc"]


def _csc_by_constructor(data, indices, indptr, n):
    return sp.csc_matrix((data, indices, indptr), shape=(n, n))


def _csc_direct(data, indices, indptr, n):
    K = sp.csc_matrix.__new__(sp.csc_matrix)
    K.data, K.indices, K.indptr, K._shape, K.maxprint = data, indices, indptr, (n, n), _MAXPRINT
    K._has_canonical_format = K._has_sorted_indices = True
    return K


def _pick_csc():
    """``_csc_direct`` where it builds what scipy's constructor builds (the same attributes), else the
    constructor: scipy's checks cost more than a small model's factorisation."""
    args = (np.ones(2), np.array([0, 1], dtype=np.int32), np.array([0, 1, 2], dtype=np.int32), 2)
    try:
        ref, fast = _csc_by_constructor(*args), _csc_direct(*args)
        same = set(vars(ref)) | {"_has_canonical_format", "_has_sorted_indices"} == set(vars(fast)) \
            and (ref != fast).nnz == 0
    except Exception:
        same = False
    return _csc_direct if same else _csc_by_constructor


_MAXPRINT = _csc_by_constructor(np.ones(1), np.zeros(1, dtype=np.int32), np.array([0, 1], dtype=np.int32), 1).maxprint


def canonical_csc(data, indices, indptr, n):
    """Square ``(n, n)`` ``scipy.sparse.csc_matrix`` of a canonical pattern (sorted, unique row
    indices per column, int32, as ``System._build_pattern`` makes it) and its ``data``; the arrays
    are not copied."""
    return _CSC(data, indices, indptr, n)


_CSC = _pick_csc()
