# Fig. 2: hoist profile (descending)
# Written by hoist-study; re-render with:  cd docs/figures/response && gnuplot fig02_profile.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig02_profile.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 3,1 title 'Fig. 2: hoist profile (descending)'
set xlabel 't [s]'
set ylabel 'l [m]'
plot 'runs/run1.csv' using "t":(column("l")*1) with lines title 'l'
set xlabel 't [s]'
set ylabel 'v [m/s]'
plot 'runs/run1.csv' using "t":(column("v")*1) with lines title 'v'
set xlabel 't [s]'
set ylabel 'a [m/s^2]'
plot 'runs/run1.csv' using "t":(column("a")*1) with lines title 'a'
unset multiplot
