# Fig. 9: constraint forces vs tension difference
# Written by hoist-study; re-render with:  cd docs/figures/tension-difference && gnuplot fig09_sleeve_forces.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,650 font ',9' linewidth 1.2
} else {
  set terminal png size 800,650
}
set termoption noenhanced
set output 'fig09_sleeve_forces.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 2,2 title 'Fig. 9: constraint forces vs tension difference'
set xlabel 't [s]'
set ylabel 'lambda_1 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_1")*1) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("lambda_1")*1) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("lambda_1")*1) with lines title 'dT=10000 N'
set xlabel 't [s]'
set ylabel 'lambda_2 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_2")*1) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("lambda_2")*1) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("lambda_2")*1) with lines title 'dT=10000 N'
set xlabel 't [s]'
set ylabel 'lambda_3 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_3")*1) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("lambda_3")*1) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("lambda_3")*1) with lines title 'dT=10000 N'
set xlabel 't [s]'
set ylabel 'lambda_4 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_4")*1) with lines title 'dT=0 N', \
     'runs/run2.csv' using "t":(column("lambda_4")*1) with lines title 'dT=5000 N', \
     'runs/run3.csv' using "t":(column("lambda_4")*1) with lines title 'dT=10000 N'
unset multiplot
