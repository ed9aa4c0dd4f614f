"""The fixed quadrature rules of the discrete problem (part of its definition, shared by every
re-implementation and by the Rust solver): the 6-point degree-4 Dunavant rule on triangles and the
3-point Gauss-Legendre rule on edges."""
import math

import numpy as np

_A, _B = 0.445948490915964886, 0.091576213509770743
_WA, _WB = 0.223381589678011466, 0.109951743655321867
#: 6-point degree-4 Dunavant rule: barycentric coordinates (npts, 3) and weights summing to 1
DUNAVANT_BARY = np.array([[_A, _A, 1 - 2 * _A], [_A, 1 - 2 * _A, _A], [1 - 2 * _A, _A, _A],
                          [_B, _B, 1 - 2 * _B], [_B, 1 - 2 * _B, _B], [1 - 2 * _B, _B, _B]])
DUNAVANT_W = np.array([_WA] * 3 + [_WB] * 3)
#: reference-triangle version ((0,0),(1,0),(0,1)): points (2, 6), weights summing to 1/2
DUNAVANT_REF_X = DUNAVANT_BARY[:, 1:].T.copy()
DUNAVANT_REF_W = 0.5 * DUNAVANT_W
#: 3-point Gauss-Legendre on [0,1], weights summing to 1
GAUSS3_S = np.array([0.5 - 0.5 * math.sqrt(0.6), 0.5, 0.5 + 0.5 * math.sqrt(0.6)])
GAUSS3_W = np.array([5.0, 8.0, 5.0]) / 18.0

