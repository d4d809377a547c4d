"""tamp.camera: images of simulated scenes and planning from them.

- ``render``: `StateRenderer`, a symbolic state rendered by a simulator camera;
- ``dataset``: randomised rendered scenes labelled with their supports (perception training data);
- ``from_images``: soft beliefs for the planner from camera images (frozen or
  planning-optimised perception).
- ``image_pair``: planning from a photographed (initial, goal) pair with no ground truth
  (``plan-images``, ``bench latplan``);
- ``geometry``: pinhole geometry of a camera (intrinsics, pose, projection, back-projection);
- ``poses``: block poses (centre, yaw) from an RGB-D image, for the arm to act on;
- ``scene_poses``: the camera pose sensor of a scene file's world (geometric TAMP's
  ``observation="camera"``): several cameras, objects told apart by colour and by their
  previous estimates, each fitted with its known model (``fit``: boxes and cylinders);
- ``latplan``: LatPlan's cylinder row, its generator's camera, and a randomised dataset of it;
- ``states``: full goal scenes a goal image shows, the most likely state of a soft state.

The image -> soft-state model itself lives in `perception` and never sees a simulator.
"""
