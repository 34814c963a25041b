# Drawn by plinth-accuracy (docs/accuracy.md) from accuracy-summary.dat.
set logscale xy
set format y '10^{%L}'
set grid
set key bottom left font ',9'
set xlabel 'cost: wall time per simulated second (ms/s)'
set terminal pngcairo size 1400,1000 font ',10'
set output 'docs/img/accuracy.png'
set multiplot layout 2,2 title 'plinth steppers: error (worst case) against cost'
set title 'time of first rocking'
set ylabel 'error of the first rocking time (s)'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:3 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:3 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:3 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:3 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:3 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'peak {/Symbol q}'
set ylabel 'relative error of the peak {/Symbol q}'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:4 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:4 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:4 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:4 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:4 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'peak u (base)'
set ylabel 'relative error of the peak u'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:5 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:5 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:5 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:5 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:5 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'overturning threshold PGA'
set ylabel 'error of the overturning PGA (g)'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:6 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:6 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:6 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:6 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:6 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
unset multiplot
set terminal svg size 1400,1000 dynamic font ',10'
set output 'docs/img/accuracy.svg'
set multiplot layout 2,2 title 'plinth steppers: error (worst case) against cost'
set title 'time of first rocking'
set ylabel 'error of the first rocking time (s)'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:3 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:3 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:3 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:3 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:3 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'peak {/Symbol q}'
set ylabel 'relative error of the peak {/Symbol q}'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:4 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:4 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:4 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:4 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:4 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'peak u (base)'
set ylabel 'relative error of the peak u'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:5 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:5 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:5 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:5 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:5 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
set title 'overturning threshold PGA'
set ylabel 'error of the overturning PGA (g)'
plot 'docs/img/accuracy-summary.dat' index 0 using 2:6 with linespoints pt 4 title 'rk4_located' noenhanced, 'docs/img/accuracy-summary.dat' index 1 using 2:6 with linespoints pt 5 title 'rk4_located+exact' noenhanced, 'docs/img/accuracy-summary.dat' index 2 using 2:6 with linespoints pt 6 title 'rk4_step_end' noenhanced, 'docs/img/accuracy-summary.dat' index 3 using 2:6 with linespoints pt 7 title 'heun_located' noenhanced, 'docs/img/accuracy-summary.dat' index 4 using 2:6 with linespoints pt 8 title 'semi_implicit_euler' noenhanced
unset multiplot
set output
