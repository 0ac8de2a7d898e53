"""proxseg: training-free segmentation and recognition of objects in RGB-D point clouds.

After Lodi Rizzini et al., "Unsupervised Range Image Segmentation and Object Recognition Using
Feature Proximity and Markov Random Field" (sections 3.1-3.4): voxels, colour / texture / shape features,
an initial clustering (Algorithm 1) with k-means, a Potts MRF solved by graph cuts, the selection
of candidate objects, and their recognition against a database of model views (FPFH, RANSAC,
ICP). Everything runs in this process, with numpy arrays in and out; the results equal the
``proxseg`` CLI's.

    import proxseg
    frame = proxseg.read_point_cloud("scene.pcd")
    result = proxseg.segment(frame)                 # labels, instances, candidates
    db = proxseg.Database("models/")
    scene = proxseg.recognize(frame, db)            # names, scores, 4x4 poses, object ids

Errors: ValueError for bad input or parameters, OSError for files that cannot be read or
written (FileNotFoundError, PermissionError, IsADirectoryError where they apply), TypeError for
arguments of the wrong kind. Frames, parameters and results pickle (multiprocessing, Dask). The computation releases the GIL; results do
not depend on the number of threads. Importing the module keeps freed memory in the process for
the next frame, as the CLI does (PROXSEG_KEEP_FREED_MEMORY=0 before the import: not).
"""

import atexit as _atexit

from . import _proxseg
from ._proxseg import Frame, __version__, build_info
from ._frame import as_frame, from_rgbd, read_point_cloud, read_rgbd, write_point_cloud
from ._open3d import from_open3d, to_open3d
from ._params import RecognitionParams, SegmentParams, parameters
from ._segment import Box, Candidate, SegmentResult, label_colors, label_colours, segment
from ._database import Database
from ._recognize import RecognitionResult, RecognizedObject, recognize, recognize_object

__all__ = [
    "Box", "Candidate", "Database", "Frame", "RecognitionParams", "RecognitionResult",
    "RecognizedObject", "SegmentParams", "SegmentResult", "__version__", "as_frame", "build_info",
    "from_open3d", "from_rgbd", "label_colors", "label_colours", "parameters", "read_point_cloud",
    "read_rgbd", "recognize", "recognize_object", "segment", "to_open3d", "write_point_cloud",
]

# At exit, the computations still running (on daemon threads: the others have been joined) are
# stopped, and waited for up to 5 s, before the interpreter finalizes: one that ended while it
# finalized aborted the process. Not threading._register_atexit, which runs before non-daemon
# threads are joined and would stop their calls too. Calls begun later raise SystemExit.
_atexit.register(_proxseg._stop_calls, 5.0)
