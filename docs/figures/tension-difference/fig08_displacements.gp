# Fig. 8: displacements vs tension difference dT = Tb2 - Tb1 (Tb1 + Tb2 = 6e4 N)
# Written by hoist-study; re-render with:  cd docs/figures/tension-difference && gnuplot fig08_displacements.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig08_displacements.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,1 title 'Fig. 8: displacements vs tension difference dT = Tb2 - Tb1 (Tb1 + Tb2 = 6e4 N)'
set xlabel 't [s]'
set ylabel 'y_c [mm]'
plot 'runs/run1.csv' using "t":(column("y_c")*1000) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("y_c")*1000) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("y_c")*1000) with lines title 'dT=10000 N'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
plot 'runs/run1.csv' using "t":(column("theta")*1000) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("theta")*1000) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("theta")*1000) with lines title 'dT=10000 N'
unset multiplot
