"""VTK XML unstructured grids (``.vtu``) written with numpy and zlib alone.

The layout is meshio's (5.3) binary one, which meshio, pyvista and ParaView read:
each array base64 inline, ``header_type="UInt32"``; compressed (``"zlib"``, ``"lzma"``)
in blocks of ``BLOCK`` bytes, each compressed alone, after the header ``[blocks,
BLOCK, size of the last block, compressed sizes]``; uncompressed (``None``) after
its byte count.  No XML tree and no meshio import: writing a step of a small scene
costs about a millisecond (``benchmarks/output_overhead.py``).
"""
import base64
import sys

import numpy as np

__all__ = ["write_vtu", "CELL_TYPES"]

BLOCK = 32768                     # bytes per compressed block (VTK's and meshio's)
CELL_TYPES = {"vertex": 1, "line": 3}
COMPRESSORS = {"zlib": "vtkZLibDataCompressor", "lzma": "vtkLZMADataCompressor"}
_VTK_TYPES = {np.dtype(t): name for t, name in (
    (np.float64, "Float64"), (np.float32, "Float32"), (np.int8, "Int8"), (np.int16, "Int16"), (np.int32, "Int32"),
    (np.int64, "Int64"), (np.uint8, "UInt8"), (np.uint16, "UInt16"), (np.uint32, "UInt32"), (np.uint64, "UInt64"))}


def _encoded(data, compression):
    """The base64 text of one array (native byte order, C order) with its header."""
    raw = np.ascontiguousarray(data).tobytes()
    if compression is None:
        return base64.b64encode(np.uint32(len(raw)).tobytes() + raw).decode()
    if compression == "zlib":
        import zlib as codec
    else:
        import lzma as codec
    blocks = [codec.compress(raw[i:i + BLOCK]) for i in range(0, len(raw), BLOCK)]
    last = len(raw) - (len(blocks) - 1) * BLOCK
    header = np.array([len(blocks), BLOCK, last] + [len(b) for b in blocks], dtype=np.uint32)
    return base64.b64encode(header.tobytes()).decode() + base64.b64encode(b"".join(blocks)).decode()


def _array(name, data, compression):
    data = np.asarray(data)
    data = data.astype(data.dtype.newbyteorder("="), copy=False)
    kind = _VTK_TYPES.get(data.dtype)
    if kind is None:
        raise TypeError(f"write_vtu: array {name!r} of dtype {data.dtype} has no VTK type")
    comps = f' NumberOfComponents="{data.shape[1]}"' if data.ndim == 2 else ""
    return (f'<DataArray type="{kind}" Name="{name}"{comps} format="binary">'
            f'{_encoded(data, compression)}</DataArray>\n')


def write_vtu(path, points, cell_type, cells, point_data=None, cell_data=None, compression="zlib"):
    """Write one block of cells of ``cell_type`` (a key of ``CELL_TYPES``) to ``path``.

    ``points`` ``(n, 3)``; ``cells`` ``(m, k)`` point indices; ``point_data`` / ``cell_data``:
    dicts of arrays ``(n,)`` or ``(n, c)`` (``(m, ...)``); ``compression``: ``"zlib"``,
    ``"lzma"`` or ``None``.
    """
    if compression is not None and compression not in COMPRESSORS:
        raise ValueError(f"write_vtu: compression must be 'zlib', 'lzma' or None, got {compression!r}")
    cells = np.asarray(cells, dtype=np.int64)
    m, k = cells.shape
    order = "LittleEndian" if sys.byteorder == "little" else "BigEndian"
    comp = f' compressor="{COMPRESSORS[compression]}"' if compression else ""
    parts = ['<?xml version="1.0"?>\n',
             f'<VTKFile type="UnstructuredGrid" version="0.1" byte_order="{order}"{comp}>\n',
             f'<UnstructuredGrid>\n<Piece NumberOfPoints="{len(points)}" NumberOfCells="{m}">\n<Points>\n',
             _array("Points", points, compression), "</Points>\n<Cells>\n",
             _array("connectivity", cells.ravel(), compression),
             _array("offsets", k * np.arange(1, m + 1, dtype=np.int64), compression),
             _array("types", np.full(m, CELL_TYPES[cell_type], dtype=np.uint8), compression), "</Cells>\n"]
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        if data:
            parts += [f"<{tag}>\n", *(_array(name, v, compression) for name, v in data.items()), f"</{tag}>\n"]
    parts.append("</Piece>\n</UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w") as f:
        f.write("".join(parts))
