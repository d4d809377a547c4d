; soft-tamp's own 5-block example, in the PlanBench problem format.
; Start: tower a-b-c (c on top) and tower d-e (e on top).
; Goal: one tower b-e-a-c-d (d on top); the optimal plan has 6 moves (12 actions).
(define (problem example-5)
  (:domain blocksworld-4ops)
  (:objects a b c d e)
  (:init
    (handempty)
    (ontable a) (on b a) (on c b) (clear c)
    (ontable d) (on e d) (clear e))
  (:goal
    (and (on e b) (on a e) (on c a) (on d c))))
