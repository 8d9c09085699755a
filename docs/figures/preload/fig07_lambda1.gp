# Fig. 7: constraint force lambda_1 vs total preload
# Written by hoist-study; re-render with:  cd docs/figures/preload && gnuplot fig07_lambda1.gp
if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {
  set terminal pngcairo size 800,500 font ',9' linewidth 1.2
} else {
  set terminal png size 800,500
}
set termoption noenhanced
set output 'fig07_lambda1.png'
set datafile separator ','
set grid
set key outside right top samplen 2
set multiplot layout 1,1 title 'Fig. 7: constraint force lambda_1 vs total preload'
set xlabel 't [s]'
set ylabel 'lambda_1 [N]'
plot 'runs/run1.csv' using "t":(column("lambda_1")*1) with lines title 'Tb1+Tb2=48000 N', \
     'runs/run2.csv' using "t":(column("lambda_1")*1) with lines title 'Tb1+Tb2=54000 N', \
     'runs/run3.csv' using "t":(column("lambda_1")*1) with lines title 'Tb1+Tb2=60000 N'
unset multiplot
