; packed, seed 0: 6 boxes fill 68% of the tray: they fit only as two columns with a finger lane between; the first box at the centre leaves no room for the last
(and
  (in o1 tray)
  (in o2 tray)
  (in o3 tray)
  (in o4 tray)
  (in o5 tray)
  (in o6 tray))
