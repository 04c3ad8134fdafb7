#!/bin/bash
# Run from the repository root after `cargo build --release -p vf-mnist --example mnist_probe`.
set -u
# 2-epoch ablation of the Voronoi decoder's beta and signed-distance weight (lr 1e-3, batch 32, 10,000 training digits; eval on test digits 1-1000)
for cfg in "10000 1,1,1,1" "10000 1,1,10,1" "100 1,1,1,1" "100 1,1,10,1" "10000 1,1,10,1 100"; do
  set -- $cfg
  echo "== beta $1 weights $2 beta_start ${3:-none}"
  if [ -n "${3:-}" ]; then target/release/examples/mnist_probe voronoi 10000 2 1e-3 32 $2 $1 $3; else target/release/examples/mnist_probe voronoi 10000 2 1e-3 32 $2 $1; fi 2>&1 | grep -E "epoch|train|Voronoi" | cut -c1-200
done
