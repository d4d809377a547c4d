"""Classical planners run beside ours on the same PDDL instances at the same per-instance time
limit (``tamp bench pddl --peers pyperplan,lama``): pyperplan's greedy best-first search with
h_FF (`gbf`) and Fast Downward's LAMA (`tamp.bench.fast_downward.lama_length`); `side_by_side`
runs them and summarises coverage, plan length and time per domain. Benchmark-only: both come
with the ``bench`` extra and nothing at plan time imports them. `slaney` holds Slaney &
Thiébaux's near-optimal Blocksworld algorithms US and GN1 (plain Python, no extra), run beside
ours by ``tamp bench random --baselines us,gn1``."""
