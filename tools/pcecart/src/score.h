#ifndef SCORE_H
#define SCORE_H

void add_score(unsigned char byte, unsigned char bcd);

#endif
