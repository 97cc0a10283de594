import numpy as np
from scipy.spatial.transform import Rotation as SciRot

import rigidkit as rk


def test_matrix_matches_scipy():
    R = rk.Rotation.random(100, 0)
    S = SciRot.from_quat(R.as_quat(scalar_first=False))
    np.testing.assert_allclose(R.as_matrix(), S.as_matrix(), atol=2e-15)
