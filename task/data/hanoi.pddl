; Tower of Hanoi in the pick-and-place style, written for soft-tamp: discs are carried one at a
; time onto a disc or onto a peg, a region on the table. One `move` picks the top disc of a
; stack and places it on a clear support that is larger (`smaller` is static: discs by size,
; every disc smaller than every peg). `task.symbolic.pickplace.hanoi` generates its problems;
; `task.symbolic.pickplace.binding` binds `move` to the motion layer (object ?d, target ?to).
(define (domain hanoi-pick-place)
  (:requirements :strips :typing)
  (:types support - object disc peg - support)
  (:predicates (on ?d - disc ?s - support) (clear ?s - support) (smaller ?d - disc ?s - support))

  (:action move
    :parameters (?d - disc ?from - support ?to - support)
    :precondition (and (on ?d ?from) (clear ?d) (clear ?to) (smaller ?d ?to))
    :effect (and (on ?d ?to) (clear ?from) (not (on ?d ?from)) (not (clear ?to)))))
