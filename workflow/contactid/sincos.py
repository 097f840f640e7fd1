"""sin x and cos x from one call of the C library's ``sincos``, for the time-stepping kernels.

The rig's and the reduced model's drive is a sum of harmonics, each with a sine and a cosine of the same angle,
evaluated every time step: about a third of a step's time. GNU libm's ``sincos`` shares its argument reduction and
polynomials with ``sin`` and ``cos`` and returns the same digits (checked in ``tests/test_sincos.py``) in about the time
of one of them. Where the C library has no ``sincos`` (macOS, Windows), ``sin_cos`` calls sine and cosine separately:
the same results, only slower.
"""

from __future__ import annotations

import ctypes
import ctypes.util

import numpy as np
from numba import njit


def _libm_sincos_address() -> int | None:
    """Return the address of the C library's ``sincos``, or None where it has none.

    The function is ``void sincos(double, double *, double *)``.
    """
    for name in (ctypes.util.find_library("m"), "libm.so.6"):
        if not name:
            continue
        try:
            return ctypes.cast(ctypes.CDLL(name).sincos, ctypes.c_void_p).value
        except (OSError, AttributeError):
            continue
    return None


_SINCOS_ADDRESS = _libm_sincos_address()
HAS_LIBM_SINCOS = _SINCOS_ADDRESS is not None

if HAS_LIBM_SINCOS:
    import llvmlite.binding as llvm
    from llvmlite import ir
    from numba import types
    from numba.core import cgutils
    from numba.extending import intrinsic

    llvm.add_symbol("sincos", _SINCOS_ADDRESS)  # the kernels' machine code (cached too) calls it by name

    @intrinsic
    def _sincos(typingctx, x):
        """Return (sin x, cos x) from libm's ``sincos`` (x in rad)."""
        sig = types.UniTuple(types.float64, 2)(types.float64)

        def codegen(context, builder, signature, args):
            dbl = ir.DoubleType()
            fnty = ir.FunctionType(ir.VoidType(), [dbl, dbl.as_pointer(), dbl.as_pointer()])
            fn = cgutils.get_or_insert_function(builder.module, fnty, "sincos")
            p_sin = cgutils.alloca_once(builder, dbl)
            p_cos = cgutils.alloca_once(builder, dbl)
            builder.call(fn, [args[0], p_sin, p_cos])
            return context.make_tuple(builder, signature.return_type, [builder.load(p_sin), builder.load(p_cos)])

        return sig, codegen

    @njit(cache=True)
    def sin_cos(x: float) -> tuple[float, float]:
        """Return (sin x, cos x) of the angle x, both from one libm ``sincos`` call.

        Parameters
        ----------
        x
            Angle [rad].

        Returns
        -------
        sin_x : float
            Sine of ``x`` [-].
        cos_x : float
            Cosine of ``x`` [-].
        """
        return _sincos(x)

else:  # pragma: no cover - platforms without GNU sincos

    @njit(cache=True)
    def sin_cos(x: float) -> tuple[float, float]:
        """Return (sin x, cos x) of the angle x.

        Sine and cosine called separately (no ``sincos`` in this C library): the same results, only slower.

        Parameters
        ----------
        x
            Angle [rad].

        Returns
        -------
        sin_x : float
            Sine of ``x`` [-].
        cos_x : float
            Cosine of ``x`` [-].
        """
        return np.sin(x), np.cos(x)
