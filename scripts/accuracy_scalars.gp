# Error vs time, one point per scalar: docs/accuracy-scalars.svg from docs/accuracy-scalars.dat.
#   gnuplot scripts/accuracy_scalars.gp      (from the repository root)
set terminal svg size 640,420 font "sans,11"
set output "docs/accuracy-scalars.svg"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "CPU time per call [ns] (paper5 nonholonomic inverse dynamics)"
set ylabel "max relative error vs 50 digits"
set key off
set grid
set xrange [50:200000]
set yrange [1e-52:1e-3]
plot "docs/accuracy-scalars.dat" using 2:3 with points pt 7 ps 1, \
     "" using 2:3:1 with labels offset char 1,0.6 left font "sans,9" noenhanced
