"""A PyTorch zip-pickle (``torch.save`` of a dict of tensors) read without torch: a restricted unpickler.

The iit-DLSLab's logs (:mod:`~wbfriction.datasets.hung_quadruped`: the Aliengo's, the Go2's) are ``traj_0.pt``
files: a zip archive holding ``<root>/data.pkl`` (a pickle of protocol 2), ``<root>/byteorder`` and each tensor's
storage as raw elements in ``<root>/data/<key>``. :func:`read_pt` reads them with NumPy alone; the pickle may name
only tensors, their storages and NumPy arrays of numbers, nothing else is imported or called.
"""

from __future__ import annotations

import collections
import pickle
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from wbfriction.exceptions import InputError

_STORAGES = {"DoubleStorage": "f8", "FloatStorage": "f4", "HalfStorage": "f2", "LongStorage": "i8",
             "IntStorage": "i4", "ShortStorage": "i2", "CharStorage": "i1", "ByteStorage": "u1", "BoolStorage": "?"}
"""torch's typed storages -> NumPy's type codes (the storage's bytes are these, in the file's byte order)."""


@dataclass(frozen=True)
class _StorageType:
    dtype: str


@dataclass(frozen=True)
class _Storage:
    values: np.ndarray  # 1-D, the storage's elements


def _rebuild_tensor(storage: _Storage, offset: int, size: tuple[int, ...], stride: tuple[int, ...],
                    requires_grad: bool = False, hooks: object = None, metadata: object = None) -> np.ndarray:
    """``torch._utils._rebuild_tensor_v2`` as NumPy: the view ``size``/``stride`` [elements] at ``offset`` of the
    storage, copied."""
    if not isinstance(storage, _Storage):
        raise ValueError(f"a tensor whose storage is a {type(storage).__name__}")
    size, stride = tuple(int(s) for s in size), tuple(int(s) for s in stride)
    if len(size) != len(stride) or any(s < 0 for s in size + stride) or offset < 0:
        raise ValueError(f"a tensor of size {size}, stride {stride}, offset {offset}")
    if 0 in size:
        return np.empty(size, dtype=storage.values.dtype)
    last = offset + sum((n - 1) * s for n, s in zip(size, stride))
    if last >= storage.values.size:
        raise ValueError(f"a tensor of size {size}, stride {stride}, offset {offset} beyond its storage of "
                         f"{storage.values.size} elements")
    item = storage.values.itemsize
    view = np.lib.stride_tricks.as_strided(storage.values[offset:], shape=size, strides=[s * item for s in stride],
                                           writeable=False)
    return np.array(view)


class _Dtype:
    """``numpy.dtype(code, align, copy)`` of a number type; its pickled state sets the byte order."""

    def __init__(self, code: object, align: object = False, copy: object = True) -> None:
        dtype = np.dtype(str(code))
        if dtype.kind not in "biufc":
            raise ValueError(f"a NumPy array of type {code!r} (only numbers are read)")
        self.dtype = dtype

    def __setstate__(self, state: tuple) -> None:
        if isinstance(state, tuple) and len(state) > 1 and state[1] in ("<", ">"):
            self.dtype = self.dtype.newbyteorder(state[1])


class _Array:
    """``numpy.core.multiarray._reconstruct(ndarray, ...)``: an array built from its pickled state."""

    def __init__(self, cls: object, shape: object = (0,), code: object = b"b") -> None:
        if cls is not _NDARRAY:
            raise ValueError("a NumPy object that is not an ndarray")
        self.array = np.empty(0)

    def __setstate__(self, state: tuple) -> None:
        _, shape, dtype, fortran, raw = state
        if not isinstance(dtype, _Dtype) or not isinstance(raw, bytes):
            raise ValueError("a NumPy array that is not of numbers")
        shape = tuple(int(n) for n in shape)
        values = np.frombuffer(raw, dtype=dtype.dtype)
        if values.size != int(np.prod(shape)):
            raise ValueError(f"a NumPy array of shape {shape} holding {values.size} values")
        self.array = values.reshape(shape, order="F" if fortran else "C").astype(dtype.dtype.newbyteorder("="))


_NDARRAY = object()


def _latin1(text: object, encoding: object = "utf-8") -> bytes:
    """``_codecs.encode(text, "latin1")``: how a pickle of protocol 2 stores bytes."""
    if not isinstance(text, str) or encoding != "latin1":
        raise ValueError(f"_codecs.encode of a {type(text).__name__} as {encoding!r}")
    return text.encode("latin1")


_ALLOWED: dict[tuple[str, str], object] = {
    ("torch._utils", "_rebuild_tensor_v2"): _rebuild_tensor,
    ("collections", "OrderedDict"): collections.OrderedDict,  # a tensor's (empty) backward hooks
    ("numpy.core.multiarray", "_reconstruct"): _Array,
    ("numpy._core.multiarray", "_reconstruct"): _Array,
    ("numpy", "ndarray"): _NDARRAY,
    ("numpy", "dtype"): _Dtype,
    ("_codecs", "encode"): _latin1,
} | {("torch", name): _StorageType(code) for name, code in _STORAGES.items()}
"""The only globals a .pt may name (anything else is refused): tensors, their storages, NumPy arrays of numbers."""


class _PtUnpickler(pickle.Unpickler):
    """A restricted unpickler of a torch zip-pickle: tensors from the archive's raw storages (``<root>/data/<key>``),
    NumPy arrays of numbers; no other global."""

    def __init__(self, archive: zipfile.ZipFile, root: str, order: str) -> None:
        super().__init__(archive.open(f"{root}/data.pkl"))
        self.archive, self.root, self.order = archive, root, order
        self.storages: dict[str, _Storage] = {}

    def find_class(self, module: str, name: str) -> Any:
        try:
            return _ALLOWED[(module, name)]
        except KeyError:
            raise pickle.UnpicklingError(f"it names {module}.{name}, which is not read (only tensors and arrays "
                                         "of numbers)") from None

    def persistent_load(self, pid: Any) -> _Storage:
        if not (isinstance(pid, tuple) and len(pid) == 5 and pid[0] == "storage"
                and isinstance(pid[1], _StorageType)):
            raise pickle.UnpicklingError(f"a persistent id {pid!r:.60} that is not a storage")
        _, kind, key, _, numel = pid
        key = str(key)
        if key not in self.storages:
            dtype = np.dtype(kind.dtype).newbyteorder(self.order)
            raw = self.archive.read(f"{self.root}/data/{key}")
            if len(raw) != int(numel) * dtype.itemsize:
                raise pickle.UnpicklingError(f"storage {key}: {len(raw)} bytes, expected {numel} of {dtype.itemsize}")
            self.storages[key] = _Storage(np.frombuffer(raw, dtype=dtype).astype(dtype.newbyteorder("=")))
        return self.storages[key]


def read_pt(path: str | Path) -> dict[str, np.ndarray]:
    """A PyTorch zip-pickle (``torch.save`` of a dict of tensors and NumPy arrays) read without torch.

    The archive holds ``<root>/data.pkl`` (the pickle), ``<root>/byteorder`` (``little`` or ``big``; little when
    missing) and each storage's raw elements in ``<root>/data/<key>``. The pickle is read by a restricted unpickler:
    the only globals it may name are ``torch._utils._rebuild_tensor_v2``, torch's typed storages
    (``torch.FloatStorage``, ...), ``collections.OrderedDict`` and NumPy's array reconstruction of number types,
    each mapped to a function of this module; nothing else is imported or called.

    Returns:
        The dict's entries as NumPy arrays (a tensor's shape and strides honoured, its values copied; native
        byte order).

    Raises:
        InputError: a file that is not a zip archive, has no ``data.pkl``, names another global, a storage the
            archive lacks or of the wrong size, a view beyond its storage, or is not a dict of arrays, naming
            the file.
    """
    path = Path(path)
    try:
        with zipfile.ZipFile(path) as archive:
            pickles = [n for n in archive.namelist() if n.count("/") == 1 and n.endswith("/data.pkl")]
            if len(pickles) != 1:
                raise InputError(f"{path}: not a PyTorch zip-pickle (no <name>/data.pkl in the archive)")
            root = pickles[0].rsplit("/", 1)[0]
            order = {"little": "<", "big": ">"}.get(_entry(archive, f"{root}/byteorder", "little"))
            if order is None:
                raise InputError(f"{path}: not a PyTorch zip-pickle (byteorder is neither little nor big)")
            doc = _PtUnpickler(archive, root, order).load()
    except InputError:
        raise
    except (zipfile.BadZipFile, pickle.UnpicklingError, EOFError, KeyError, ValueError, TypeError, AttributeError,
            IndexError, OSError) as exc:
        raise InputError(f"{path}: not a readable PyTorch zip-pickle ({type(exc).__name__}: "
                         f"{' '.join(str(exc).split())})") from None
    if not isinstance(doc, dict):
        raise InputError(f"{path}: a PyTorch zip-pickle of a {type(doc).__name__}, expected a dict of tensors")
    out = {}
    for key, value in doc.items():
        value = value.array if isinstance(value, _Array) else value
        if not isinstance(value, np.ndarray):
            raise InputError(f"{path}: '{key}' is a {type(value).__name__}, expected a tensor or an array")
        out[str(key)] = value
    return out


def _entry(archive: zipfile.ZipFile, name: str, default: str) -> str:
    try:
        return archive.read(name).decode("ascii").strip()
    except KeyError:
        return default
