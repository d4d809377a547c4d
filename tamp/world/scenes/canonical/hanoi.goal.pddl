; hanoi, seed 0: 5 discs from peg1 to peg3 (31 moves at best): a disc goes only on a wider one or an empty peg, which holds no two side by side
(and
  (in d5 peg3)
  (on d1 d2)
  (on d2 d3)
  (on d3 d4)
  (on d4 d5))
