# Fig. 6: cage lateral and torsional displacement vs total preload (Tb1 = Tb2)
# Written by hoist-study; re-render with:  cd docs/figures/preload && gnuplot fig06_displacements.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig06_displacements.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,1 title 'Fig. 6: cage lateral and torsional displacement vs total preload (Tb1 = Tb2)'
set xlabel 't [s]'
set ylabel 'y_c [mm]'
plot 'runs/run1.csv' using "t":(column("y_c")*1000) with lines title 'Tb1+Tb2=48000 N', \
     'runs/run2.csv' using "t":(column("y_c")*1000) with lines title 'Tb1+Tb2=54000 N', \
     'runs/run3.csv' using "t":(column("y_c")*1000) with lines title 'Tb1+Tb2=60000 N'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
plot 'runs/run1.csv' using "t":(column("theta")*1000) with lines title 'Tb1+Tb2=48000 N', \
     'runs/run2.csv' using "t":(column("theta")*1000) with lines title 'Tb1+Tb2=54000 N', \
     'runs/run3.csv' using "t":(column("theta")*1000) with lines title 'Tb1+Tb2=60000 N'
unset multiplot
