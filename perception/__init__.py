"""perception: the rendering-independent image -> soft support model.

``perception.model.SupportModel`` maps images (B, 3, H, W) and entity boxes (B, N, 4) to a soft
support matrix F (B, N, N+K) with a CNN backbone, ROI pooling and the directional bilinear head
of the paper. Data generation, training, checkpoints and planning from images come next (see
the open perception issue). ``import perception`` stays light: no torch until a submodule needs it.
"""

from pathlib import Path

CHECKPOINT = Path(__file__).with_name("support.pt")  # the shipped weights (see its meta)
