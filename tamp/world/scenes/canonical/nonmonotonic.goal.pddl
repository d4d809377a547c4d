; nonmonotonic, seed 0: target t at the back of a kerbed alcove behind 3 objects: f1 blocks its fingers, f2 its palm; both must go out and come back
(and
  (in t goal_zone)
  (in f1 alcove)
  (in f2 alcove)
  (in f3 alcove))
