# Fig. 10: displacements vs eccentric load Fa
# Written by hoist-study; re-render with:  cd docs/figures/eccentric-load && gnuplot fig10_displacements.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig10_displacements.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,1 title 'Fig. 10: displacements vs eccentric load Fa'
set xlabel 't [s]'
set ylabel 'y_c [mm]'
plot 'runs/run1.csv' using "t":(column("y_c")*1000) with lines title 'Fa=1000 N', \
     'runs/run2.csv' using "t":(column("y_c")*1000) with lines title 'Fa=2000 N', \
     'runs/run3.csv' using "t":(column("y_c")*1000) with lines title 'Fa=3000 N'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
plot 'runs/run1.csv' using "t":(column("theta")*1000) with lines title 'Fa=1000 N', \
     'runs/run2.csv' using "t":(column("theta")*1000) with lines title 'Fa=2000 N', \
     'runs/run3.csv' using "t":(column("theta")*1000) with lines title 'Fa=3000 N'
unset multiplot
