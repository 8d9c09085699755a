# Fig. 11: constraint forces lambda_1, lambda_3 vs eccentric load
# Written by hoist-study; re-render with:  cd docs/figures/eccentric-load && gnuplot fig11_sleeve_forces.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig11_sleeve_forces.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,1 title 'Fig. 11: constraint forces lambda_1, lambda_3 vs eccentric load'
set xlabel 't [s]'
set ylabel 'lambda_1 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_1")*1) with lines title 'Fa=1000 N', \
     'runs/run2.csv' using "t":(column("lambda_1")*1) with lines title 'Fa=2000 N', \
     'runs/run3.csv' using "t":(column("lambda_1")*1) with lines title 'Fa=3000 N'
set xlabel 't [s]'
set ylabel 'lambda_3 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_3")*1) with lines title 'Fa=1000 N', \
     'runs/run2.csv' using "t":(column("lambda_3")*1) with lines title 'Fa=2000 N', \
     'runs/run3.csv' using "t":(column("lambda_3")*1) with lines title 'Fa=3000 N'
unset multiplot
