; tall, seed 0: a 10-cube tower (0.41 m) 0.67 m out, at the edge of the arm's reach, to rebuild upside down on a near pad
(and
  (in c10 near_pad)
  (on c9 c10)
  (on c8 c9)
  (on c7 c8)
  (on c6 c7)
  (on c5 c6)
  (on c4 c5)
  (on c3 c4)
  (on c2 c3)
  (on c1 c2))
