# Fig. 12: displacements vs cage mass (J in proportion)
# Written by hoist-study; re-render with:  cd docs/figures/mass && gnuplot fig12_displacements.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig12_displacements.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,1 title 'Fig. 12: displacements vs cage mass (J in proportion)'
set xlabel 't [s]'
set ylabel 'y_c [mm]'
plot 'runs/run1.csv' using "t":(column("y_c")*1000) with lines title 'm=800 kg, J=870', \
     'runs/run2.csv' using "t":(column("y_c")*1000) with lines title 'm=1200 kg, J=1305', \
     'runs/run3.csv' using "t":(column("y_c")*1000) with lines title 'm=1600 kg, J=1740'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
plot 'runs/run1.csv' using "t":(column("theta")*1000) with lines title 'm=800 kg, J=870', \
     'runs/run2.csv' using "t":(column("theta")*1000) with lines title 'm=1200 kg, J=1305', \
     'runs/run3.csv' using "t":(column("theta")*1000) with lines title 'm=1600 kg, J=1740'
unset multiplot
