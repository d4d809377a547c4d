; blocked, seed 0: target t hemmed in by 4 neighbours 4-8 mm away (a finger is 2.4 cm thick): no top-down grasp is collision-free until two opposite neighbours move
(and
  (in t goal_zone))
