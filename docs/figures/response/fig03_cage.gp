# Fig. 3: cage longitudinal, lateral and torsional displacement
# Written by hoist-study; re-render with:  cd docs/figures/response && gnuplot fig03_cage.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,650 font ',9' linewidth 1.2
} else {
  set terminal png size 800,650
}
set termoption noenhanced
set output 'fig03_cage.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 3,1 title 'Fig. 3: cage longitudinal, lateral and torsional displacement'
set xlabel 't [s]'
set ylabel 'x_c [mm]'
plot 'runs/run1.csv' using "t":(column("x_c")*1000) with lines title 'x_c'
set xlabel 't [s]'
set ylabel 'y_c [mm]'
plot 'runs/run1.csv' using "t":(column("y_c")*1000) with lines title 'y_c'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
plot 'runs/run1.csv' using "t":(column("theta")*1000) with lines title 'theta'
unset multiplot
