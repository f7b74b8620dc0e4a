# Work-precision figure from examples/work_precision's CSV (docs/accuracy.md, "Integrators").
#   build-*/examples/work_precision > wp.csv
#   gnuplot -e "in='wp.csv'; out='docs/figures/work-precision.png'" scripts/work_precision.gp
if (!exists("in")) in = 'wp.csv'
if (!exists("out")) out = 'work-precision.png'
set terminal pngcairo size 1100,480 enhanced font ',10'
set output out
set datafile separator ','
set logscale xy
set format x '10^{%T}'
set format y '10^{%T}'
set grid
set key bottom left
set xlabel 'CPU time per run [s] (best of 3)'
set ylabel 'max |x(T) - x_{ref}(T)| over (q, η)'
sel(p, m, col) = (strcol(1) eq p && strcol(2) eq m) ? column(col) : 1/0
set multiplot layout 1,2
set title 'paper-circle (closed loop, 20 s)'
plot for [m in 'rk4 dopri5 rosenbrock4'] in every ::1 using (sel('circle', m, 9)):(sel('circle', m, 5)) with linespoints pt 7 title m
set title 'unforced paper5 (τ = 0, 2 s, chaotic arm)'
plot for [m in 'rk4 dopri5 rosenbrock4'] in every ::1 using (sel('unforced', m, 9)):(sel('unforced', m, 5)) with linespoints pt 7 title m
unset multiplot
