#include <iostream>

#include "soft_body_sim/tools/simulate.h"

int main(int argc, char** argv)
{
  return soft_body_sim::runSimulate(std::vector<std::string>(argv + 1, argv + argc), std::cout, std::cerr);
}
