; A pick-and-place domain of your own, run at motion level: items are picked from the table,
; from another item or from a region, and put down, stacked or put into a region. Its binding
; (tray.binding.json) says which action picks and which places what, and how a scene's
; geometry reads as its state: `tamp run --scene tray --domain examples/domains/tray.pddl
; --binding examples/domains/tray.binding.json --goal '(and (in d tray) (on b c))'`.
(define (domain tray-pick-place)
  (:requirements :strips :typing)
  (:types item region)
  (:predicates (on ?x - item ?y - item) (in ?x - item ?r - region) (ontable ?x - item)
               (clear ?x - item) (holding ?x - item) (handempty))

  (:action pick-from-table
    :parameters (?x - item)
    :precondition (and (ontable ?x) (clear ?x) (handempty))
    :effect (and (holding ?x) (not (ontable ?x)) (not (handempty))))

  (:action pick-from-region
    :parameters (?x - item ?r - region)
    :precondition (and (in ?x ?r) (clear ?x) (handempty))
    :effect (and (holding ?x) (not (in ?x ?r)) (not (handempty))))

  (:action unstack
    :parameters (?x - item ?y - item)
    :precondition (and (on ?x ?y) (clear ?x) (handempty))
    :effect (and (holding ?x) (clear ?y) (not (on ?x ?y)) (not (handempty))))

  (:action stack
    :parameters (?x - item ?y - item)
    :precondition (and (holding ?x) (clear ?y))
    :effect (and (on ?x ?y) (handempty) (not (holding ?x)) (not (clear ?y))))

  (:action put-in
    :parameters (?x - item ?r - region)
    :precondition (holding ?x)
    :effect (and (in ?x ?r) (handempty) (not (holding ?x))))

  (:action put-down
    :parameters (?x - item)
    :precondition (holding ?x)
    :effect (and (ontable ?x) (handempty) (not (holding ?x)))))
