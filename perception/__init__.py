"""perception: the rendering-independent image -> soft support model.

- ``perception.segment``: entity boxes by colour (OpenCV), with one-line errors for hidden blocks;
- ``perception.model.SupportModel``: images (B, 3, H, W) and entity boxes (B, N, 4) -> a soft
  support matrix F (B, N, N+K) (CNN backbone, ROI pooling, the directional bilinear head);
- ``perception.data`` / ``perception.train``: dataset files, training, evaluation, checkpoints;
- ``perception.perceive.Perceiver``: segmentation + model, blur, KL anchors.

``CHECKPOINT`` is the shipped model (its meta says which commands and seeds made it). Rendering
lives in ``tamp`` (``tamp.camera.render``, ``tamp.camera.dataset``); this package never
imports a simulator. ``import perception`` stays light: no torch until a submodule needs it.
"""

from pathlib import Path

CHECKPOINT = Path(__file__).with_name("support.pt")  # the shipped weights (see its meta)
