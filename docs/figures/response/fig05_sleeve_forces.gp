# Fig. 5: guide-sleeve constraint forces
# Written by hoist-study; re-render with:  cd docs/figures/response && gnuplot fig05_sleeve_forces.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig05_sleeve_forces.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 1,1 title 'Fig. 5: guide-sleeve constraint forces'
set xlabel 't [s]'
set ylabel 'lambda_k [N]'
plot 'runs/run1.csv' using "t":"lambda_1" with lines title 'lambda_1', \
     'runs/run1.csv' using "t":"lambda_2" with lines dt 2 title 'lambda_2', \
     'runs/run1.csv' using "t":"lambda_3" with lines title 'lambda_3', \
     'runs/run1.csv' using "t":"lambda_4" with lines dt 2 title 'lambda_4'
unset multiplot
