; sorting, seed 0: 8 objects of 3 colours among 12 posts 10 cm tall: a post 4.5-6 cm from each object blocks one of its two top-down grasp axes
(and
  (in o1 green_zone)
  (in o2 yellow_zone)
  (in o3 green_zone)
  (in o4 red_zone)
  (in o5 yellow_zone)
  (in o6 yellow_zone)
  (in o7 red_zone)
  (in o8 green_zone))
